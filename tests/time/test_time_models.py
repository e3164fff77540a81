"""The explicit-time example models against closed forms, through the Python API and the CLI.

* models/rotating_hoop.py: equilibria theta = 0 (stable for w^2 < g/R, small oscillations at
  Omega^2 = g/R - w^2) and theta* = arccos(g/(R w^2)) (stable for w^2 > g/R, Omega^2 =
  w^2 sin(theta*)^2); the Jacobi integral E = T2 - T0 + V is conserved while T + V is not.
* models/driven_pendulum.py (Kapitza): the inverted position is stable for a^2 w^2 > 2 g l and
  unstable below, shown by simulation over 300 forcing periods on both sides.
* models/slider_crank.py: the slider follows x(t) = r cos(w t) + sqrt(L^2 - r^2 sin(w t)^2).
"""

import math
import subprocess
import sys

import numpy as np
import pytest

from lagrange_gen import simulate
from time_util import ROOT

G, R = 9.81, 1.0


@pytest.fixture(scope="module")
def gen(time_module):
    return time_module


def oscillation_frequency(t, x):
    """Angular frequency of x(t) - mean from the times of its upward zero crossings."""
    y = x - x.mean()
    up = np.flatnonzero((y[:-1] < 0) & (y[1:] >= 0))
    times = t[up] - y[up] * (t[up + 1] - t[up]) / (y[up + 1] - y[up])
    return 2 * math.pi * (len(times) - 1) / (times[-1] - times[0])


@pytest.mark.parametrize("w", [2.0, 5.0])
def test_hoop_equilibrium_and_small_oscillations(gen, w):
    mod = gen("rotating_hoop")
    p = {"m": 1.0, "R": R, "g": G, "w": w}
    if w**2 < G / R:
        theta_eq, omega = 0.0, math.sqrt(G / R - w**2)
    else:
        theta_eq = math.acos(G / (R * w**2))
        omega = w * math.sin(theta_eq)
        # theta = 0 is an equilibrium but unstable: d(theta'')/d(theta) > 0 there
        assert mod.accelerations([1e-6], [0.0], 0.0, p)[0] > 0
    assert abs(mod.accelerations([theta_eq], [0.0], 0.3, p)[0]) < 1e-12
    amp = 1e-3
    tr = simulate(mod, "rk4", [theta_eq + amp], [0.0], t_end=20 * 2 * math.pi / omega,
                  h=2 * math.pi / omega / 400, params=p)
    assert abs(tr.q[:, 0].mean() - theta_eq) < 10 * amp**2
    assert np.abs(tr.q[:, 0] - theta_eq).max() < 1.01 * amp                 # stable
    assert oscillation_frequency(tr.t, tr.q[:, 0]) == pytest.approx(omega, rel=1e-5)


def test_hoop_jacobi_integral_is_conserved_and_T_plus_V_is_not(gen):
    mod = gen("rotating_hoop")
    p = {"m": 1.0, "R": R, "g": G, "w": 5.0}
    tr = simulate(mod, "midpoint", [0.3], [0.0], t_end=200.0, h=0.01, params=p, save_every=10)
    th, thd = tr.q[:, 0], tr.v[:, 0]
    jacobi = thd**2 / 2 - 25.0 * np.sin(th) ** 2 / 2 - G * np.cos(th)    # by hand, m = R = 1
    np.testing.assert_allclose(tr.energy, jacobi, rtol=0, atol=1e-12)
    assert np.abs(tr.energy - tr.energy[0]).max() < 1e-3                  # bounded, O(h^2)
    first, last = (np.abs(tr.energy[s] - tr.energy[0]).max() for s in (slice(0, 200), slice(-200, None)))
    assert last < 1.5 * first + 1e-12                                      # no drift
    t_plus_v = thd**2 / 2 + 25.0 * np.sin(th) ** 2 / 2 - G * np.cos(th)
    assert np.ptp(t_plus_v) > 1.0


@pytest.mark.parametrize("w, stable", [(100.0, True), (92.0, True), (86.0, False), (80.0, False)])
def test_kapitza_inverted_position(gen, w, stable):
    """a = 0.05, l = 1: a^2 w^2 / (2 g l) = 1.27, 1.08 (stable), 0.94, 0.82 (unstable).

    The run starts at w t0 = pi/2, where the pivot is at rest: started at t0 = 0 with theta' = 0
    the bob would carry the fast motion's velocity a w sin(theta) / l (1 rad/s here) as a slow
    velocity, enough to leave the effective potential's well at these parameters."""
    mod = gen("driven_pendulum")
    p = {"m": 1.0, "l": 1.0, "g": G, "a": 0.05, "w": w}
    period = 2 * math.pi / w
    tr = simulate(mod, "rk4", [math.pi - 0.2], [0.0], t0=period / 4, t_end=period / 4 + 300 * period,
                  h=period / 50, params=p, save_every=5)
    away = np.abs(tr.q[:, 0] - math.pi).max()
    assert (away < 0.3) if stable else (away > 1.0), away


def test_slider_follows_closed_form_kinematics(gen):
    mod = gen("slider_crank")
    r, L, w = 0.3, 1.0, 6.0
    q0 = [0.0, r + L, 0.1]
    v0 = [r * w / L, 0.0, 0.0]
    tr = simulate(mod, "rattle", q0, v0, t_end=3.0, h=2e-3)
    x = r * np.cos(w * tr.t) + np.sqrt(L**2 - (r * np.sin(w * tr.t)) ** 2)
    np.testing.assert_allclose(tr.q[:, 1], x, rtol=0, atol=1e-10)
    np.testing.assert_allclose(tr.q[:, 0], np.arcsin(r * np.sin(w * tr.t) / L), rtol=0, atol=1e-10)


@pytest.mark.parametrize("stem, args, expect", [
    ("rotating_hoop", ["--method", "midpoint", "--q0", "0.3", "--h", "0.01", "--t-end", "2"], "rotating_hoop"),
    ("driven_pendulum", ["--method", "rk4", "--q0", "3.0", "--h", "0.001", "--t-end", "1"], "driven_pendulum"),
    ("slider_crank", ["--method", "rattle", "--q0", "0", "1.3", "0.1", "--v0", "1.8", "0", "0",
                      "--h", "0.002", "--t-end", "1"], "slider_crank"),
])
def test_cli_runs_each_model(tmp_path, stem, args, expect):
    out = tmp_path / "run.npz"
    proc = subprocess.run([sys.executable, "-m", "lagrange_gen.cli", "simulate", str(ROOT / "models" / f"{stem}.py"),
                           *args, "--gen-dir", str(tmp_path), "--out", str(out)],
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr
    assert expect in proc.stdout
    data = np.load(out)
    assert np.isfinite(data["q"]).all() and data["q"].shape[0] > 10
