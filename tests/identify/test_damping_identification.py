"""Viscous damping by the wavelet logarithmic decrement (lecture slide 31, issue 7 item 4).

Free decay of m x'' + c x' + k x = 0 from its exact solution
x = A exp(-sigma t) cos(omega_d t + phi), sigma = c / (2m), omega_d = sqrt(k/m - sigma^2).
"""

import math

import numpy as np
import pytest
import pywt

from lagrange_gen.identify import IdentificationError, identify_damping



def free_decay(m, k, c, t_end, dt, x0=1.0, v0=0.0):
    """Exact under-damped solution sampled at t = 0, dt, ... (shapes (N,))."""
    sigma = c / (2 * m)
    omega_d = math.sqrt(k / m - sigma**2)
    t = np.arange(0.0, t_end, dt)
    # x = e^{-sigma t} (x0 cos(omega_d t) + (v0 + sigma x0) / omega_d sin(omega_d t))
    x = np.exp(-sigma * t) * (x0 * np.cos(omega_d * t)
                              + (v0 + sigma * x0) / omega_d * np.sin(omega_d * t))
    return t, x


@pytest.mark.parametrize("period", [None, 2 * math.pi])
def test_free_decay_recovers_c(period):
    """m = k = 1, c = 0.05 over 24 periods: c within 2% asked; the fit gives far better."""
    t, x = free_decay(1.0, 1.0, 0.05, 150.0, 0.01)
    fit = identify_damping(t, x, period=period)
    assert abs(fit.c / 0.05 - 1) < 1e-4
    assert abs(fit.decay_rate - 0.025) < 1e-4 * 0.025
    assert abs(fit.omega_d / math.sqrt(1 - 0.025**2) - 1) < 1e-6
    assert abs(fit.k - 1.0) < 1e-5 and abs(fit.zeta - 0.025) < 1e-5
    assert (fit.window[1] - fit.window[0]) / fit.period > 10  # fitted over many periods


def test_mass_scales_c_and_noise_is_tolerated():
    """m = 2, k = 3, c = 0.12 (sigma = 0.03), 1% noise, 20 samples per period: c within 2%."""
    m, k, c = 2.0, 3.0, 0.12
    t, x = free_decay(m, k, c, 150.0, 2 * math.pi / math.sqrt(k / m) / 20, x0=0.5, v0=1.0)
    x = x + 0.01 * np.abs(x).max() * np.random.default_rng(7).standard_normal(len(x))
    fit = identify_damping(t, x, m=m)
    assert abs(fit.c / c - 1) < 0.02
    assert abs(fit.decay_rate / (c / (2 * m)) - 1) < 0.02
    assert abs(fit.k / k - 1) < 0.01


def test_lecture_two_point_formula():
    """sigma = log(|W(nT)| / |W(mT)|) / ((m - n) T) at the matched scale, for n = 6, m = 16.

    Checks the principle the fit relies on, with PyWavelets directly (no package code).
    """
    t, x = free_decay(1.0, 1.0, 0.05, 150.0, 0.01)
    omega_d = math.sqrt(1 - 0.025**2)
    period = 2 * math.pi / omega_d
    scale = pywt.scale2frequency("cmor1.5-1.0", 1.0) * period / 0.01
    modulus = np.abs(pywt.cwt(x, [scale], "cmor1.5-1.0", method="fft")[0][0])
    n, m = 6, 16
    w_n, w_m = (modulus[int(round(j * period / 0.01))] for j in (n, m))
    assert abs(math.log(w_n / w_m) / ((m - n) * period) / 0.025 - 1) < 1e-3


def test_refusals():
    t, x = free_decay(1.0, 1.0, 0.05, 150.0, 0.01)
    with pytest.raises(IdentificationError, match="uniformly sampled"):
        identify_damping(t**1.01, x)
    with pytest.raises(IdentificationError, match="too short: 6.4 periods recorded"):
        identify_damping(t[:4000], x[:4000])  # the edges alone take 7 periods
    with pytest.raises(IdentificationError, match=r"too short: 1.0 period\(s\) usable"):
        identify_damping(t[:5000], x[:5000])  # 8 periods: 1 left between the edges
    with pytest.raises(IdentificationError, match="no oscillation"):
        identify_damping(t, np.exp(-0.1 * t))
    with pytest.raises(IdentificationError, match="same length"):
        identify_damping(t, x[:-1])
    with pytest.raises(IdentificationError, match="too few samples"):
        identify_damping(t[:10], x[:10])
    with pytest.raises(IdentificationError, match="m must be positive"):
        identify_damping(t, x, m=0.0)
    with pytest.raises(IdentificationError, match="is real"):
        identify_damping(t, x, wavelet="morl")
