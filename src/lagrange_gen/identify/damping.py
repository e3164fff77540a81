"""Viscous damping from a free decay by the wavelet logarithmic decrement (lecture slide 31).

For m x'' + c x' + k x = 0 (under-damped), x(t) = A exp(-sigma t) cos(omega_d t + phi) with
decay rate sigma = c / (2 m) and damped frequency omega_d = sqrt(k/m - sigma^2). Lamarque, Pernot
and Cuer (J. Sound Vib. 235(3), 2000) show that the continuous wavelet transform W(b, a) at a fixed
analysing scale a inherits the envelope: |W(b, a)| ∝ exp(-sigma b), hence their decrement
sigma = log(|W(nT, a)| / |W(mT, a)|) / ((m - n) T) (the lecture writes this rate as "c").

Method. With the complex Morlet wavelet (PyWavelets 'cmorB-C') the transform of the decaying
cosine is, up to terms of relative size exp(-pi^2 B C^2), A' exp((-sigma + i omega_d) b): its
modulus decays exactly like the envelope and its phase advances like omega_d b, at any scale.
The scale is matched to the oscillation (a = C / (f_d dt), f_d from the spectrum peak or from the
given period), which maximizes |W| and rejects other frequencies. Instead of the two-point formula,
log|W(b)| and the unwrapped phase are fitted by straight lines over every sample b of the usable
part of the record: the ends are dropped where the wavelet overhangs the record (4 standard
deviations of its Gaussian window), and so is the tail where |W| sinks towards the noise floor.

Assumptions: one dominant under-damped mode, uniform sampling, additive noise, several periods
recorded (about 3.5 periods are lost at each end with the default wavelet).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import IdentificationError
from .wavelet import import_pywt

MIN_PERIODS = 2.0   # the log-modulus line is fitted over at least this many periods
EDGE_STD = 4.0      # ends dropped: this many Gaussian standard deviations of the wavelet window


@dataclass
class DampingFit:
    """Identified free decay of m x'' + c x' + k x = 0.

    decay_rate: sigma = c / (2 m), the envelope being exp(-sigma t); c: viscous coefficient
    2 m sigma; m: the mass used; omega_d, period: damped angular frequency and period 2 pi/omega_d;
    omega_0: undamped frequency sqrt(omega_d^2 + sigma^2); zeta: damping ratio sigma / omega_0;
    k: stiffness m omega_0^2; log_decrement: sigma * period; decay_rate_stderr: formal standard
    error of the line fit (samples are correlated, so it is optimistic); scale: analysing scale (in
    samples); window: (t_start, t_end) of the fitted part; rms: residual rms of log|W|.
    """

    decay_rate: float
    c: float
    m: float
    omega_d: float
    period: float
    omega_0: float
    zeta: float
    k: float
    log_decrement: float
    decay_rate_stderr: float
    scale: float
    window: tuple
    rms: float

    def summary(self):
        """Multi-line text of the parameters (what the CLI prints)."""
        t0, t1 = self.window
        return "\n".join([
            f"free decay, wavelet logarithmic decrement over t in [{t0:.6g}, {t1:.6g}] "
            f"({(t1 - t0) / self.period:.1f} periods, scale {self.scale:.4g} samples)",
            f"decay rate sigma = c/(2m) = {self.decay_rate:.6g} +- {self.decay_rate_stderr:.2g}",
            f"c = {self.c:.6g}  (m = {self.m:g})",
            f"damped period T = {self.period:.6g}, omega_d = {self.omega_d:.6g}, "
            f"omega_0 = {self.omega_0:.6g}",
            f"damping ratio zeta = {self.zeta:.6g}, logarithmic decrement = "
            f"{self.log_decrement:.6g}, k = m omega_0^2 = {self.k:.6g}",
        ])


def _uniform_samples(t, x):
    """Validated (t, x) of shape (N,) and the sampling step; t must be uniform."""
    t, x = np.asarray(t, dtype=float), np.asarray(x, dtype=float)
    if t.ndim != 1 or t.shape != x.shape:
        raise IdentificationError(f"t and x must be 1-D of the same length, got shapes "
                                  f"{t.shape} and {x.shape}")
    if len(t) < 32:
        raise IdentificationError(f"too few samples: {len(t)}, need at least 32 for a free decay")
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(x))):
        raise IdentificationError("t or x holds NaN or infinite samples; remove them first")
    steps = np.diff(t)
    dt = float(steps.mean())
    if dt <= 0 or np.abs(steps - dt).max() > 1e-6 * dt:
        raise IdentificationError("t must be increasing and uniformly sampled (the wavelet "
                                  "transform assumes a constant step); resample first")
    return t, x, dt


def _spectral_period(x, dt):
    """Period of the largest spectral peak (zero-padded FFT, parabolic interpolation)."""
    n = 4 * len(x)
    spectrum = np.abs(np.fft.rfft(x * np.hanning(len(x)), n))
    spectrum[0] = 0.0  # the mean is not an oscillation
    i = int(np.argmax(spectrum))
    if i < 4 * MIN_PERIODS or i >= len(spectrum) - 1:
        # The padded spectrum has 4 bins per cycle over the record: fewer than MIN_PERIODS cycles.
        raise IdentificationError(
            f"no oscillation: the spectrum of x peaks at {i / 4:.1f} cycles over the record, need "
            f"at least {MIN_PERIODS:g} (a free decay of an under-damped oscillator)")
    a, b, c = np.log(spectrum[i - 1:i + 2] + np.finfo(float).tiny)
    shift = 0.5 * (a - c) / (a - 2 * b + c) if a - 2 * b + c != 0 else 0.0
    return n * dt / (i + shift)


def _noise_gain(pywt, wavelet, scale):
    """|W| of unit white noise: the l2 norm of the transform kernel at this scale."""
    half = int(np.ceil(8 * scale)) + 1
    delta = np.zeros(2 * half + 1)
    delta[half] = 1.0
    kernel = pywt.cwt(delta, [scale], wavelet, method="fft")[0][0]
    return float(np.sqrt(np.sum(np.abs(kernel) ** 2)))


def _noise_sigma(x):
    """Robust noise level of x (N,) from fourth differences (a sampled sinusoid barely has any)."""
    d4 = np.diff(x, 4)
    return float(1.4826 * np.median(np.abs(d4 - np.median(d4))) / np.sqrt(70.0))


def _usable(modulus, edge, threshold):
    """Indices of the fitted part: inside the edges, up to where |W| first sinks below threshold."""
    inner = np.arange(edge, len(modulus) - edge)
    below = np.flatnonzero(modulus[inner] < threshold)
    return inner[:below[0]] if len(below) else inner


def identify_damping(t, x, period=None, scale=None, m=1.0, wavelet="cmor1.5-1.0", floor=1e-3):
    """Decay rate and viscous coefficient of a free decay x(t), shapes (N,), t uniform.

    The model is m x'' + c x' + k x = 0 with envelope exp(-sigma t), sigma = c / (2 m): the
    returned DampingFit.decay_rate is sigma (the lecture's "c" in c = log(|W(nT)|/|W(mT)|) /
    ((m - n) T)) and DampingFit.c = 2 m sigma is the dashpot coefficient for the given mass m.
    period: damped period T (None: from the spectrum peak); it only sets the analysing scale.
    scale: analysing scale in samples (None: matched to T). wavelet: a PyWavelets complex Morlet.
    floor: the fit stops where |W| falls below this fraction of its maximum (or 20 times its
    noise level, whichever is larger). Raises IdentificationError when too little is recorded.
    """
    pywt = import_pywt()
    t, x, dt = _uniform_samples(t, x)
    for name, value in (("m", m), ("period", period), ("scale", scale)):
        if value is not None and not value > 0:
            raise IdentificationError(f"{name} must be positive, got {value}")
    x = x - x.mean()  # the Morlet wavelet nearly ignores a constant; removing it costs nothing
    guess = float(period) if period else _spectral_period(x, dt)
    w = pywt.ContinuousWavelet(wavelet)
    if not w.complex_cwt:
        raise IdentificationError(f"wavelet {wavelet!r} is real: use a complex Morlet 'cmorB-C'")
    a = float(scale) if scale else pywt.scale2frequency(w, 1.0) * guess / dt
    coef = pywt.cwt(x, [a], w, method="fft")[0][0]
    modulus = np.abs(coef)
    edge = int(np.ceil(EDGE_STD * np.sqrt(w.bandwidth_frequency / 2) * a))
    if len(x) <= 2 * edge:
        raise IdentificationError(
            f"too short: {len(x) * dt / guess:.1f} periods recorded, the wavelet window needs "
            f"{2 * edge * dt / guess:.1f} for its edges plus {MIN_PERIODS:g} to fit")
    peak = modulus[edge:len(x) - edge].max()
    threshold = max(floor * peak, 20 * _noise_sigma(x) * _noise_gain(pywt, w, a))
    sel = _usable(modulus, edge, threshold)
    if len(sel) < 8 or (t[sel[-1]] - t[sel[0]]) < MIN_PERIODS * guess:
        span = (t[sel[-1]] - t[sel[0]]) / guess if len(sel) else 0.0
        raise IdentificationError(
            f"too short: {span:.1f} period(s) usable after dropping {edge * dt / guess:.1f} at "
            f"each end and the tail under the noise floor; need at least {MIN_PERIODS:g}")
    return _decay_fit(t[sel], coef[sel], m, a)


def _decay_fit(b, coef, m, scale):
    """Straight-line fits of log|W| and of the unwrapped phase against b; shapes (P,)."""
    centred = b - b.mean()
    spread = float(centred @ centred)
    log_mod = np.log(np.abs(coef))
    slope = float(centred @ log_mod) / spread
    resid = log_mod - log_mod.mean() - slope * centred
    omega_d = abs(float(centred @ np.unwrap(np.angle(coef))) / spread)
    sigma = -slope
    omega_0 = float(np.hypot(omega_d, sigma))
    period = 2 * np.pi / omega_d
    rms = float(np.sqrt(resid @ resid / len(b)))
    stderr = rms / np.sqrt(spread) if len(b) > 2 else float("inf")
    return DampingFit(decay_rate=sigma, c=2 * m * sigma, m=float(m), omega_d=omega_d,
                      period=period, omega_0=omega_0, zeta=sigma / omega_0, k=m * omega_0**2,
                      log_decrement=sigma * period, decay_rate_stderr=stderr, scale=scale,
                      window=(float(b[0]), float(b[-1])), rms=rms)
