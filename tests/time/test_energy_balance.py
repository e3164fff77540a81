"""The energy balance E - E0 - W = 0 (steppers/core/work.py): W, the work of non-conservative forces,
dissipation and explicit time, integrated by the run loop with the corrected trapezoid rule.

On a damped, forced model the balance error max |E - E0 - W| over the run converges at the
method's order p, capped at 4 by the quadrature (order 2 for constrained models, where the
acceleration of the h^2 correction is not available); E - E0 itself is O(1) there."""

import math
import subprocess
import sys

import numpy as np
import pytest

from lagrange_gen import simulate
from lagrange_gen.run import fixed_driver as fixed_run
from lagrange_gen.steppers.core.registry import CONSTRAINED_METHODS, INFO, METHODS, NONSMOOTH_METHODS
from time_util import ROOT

UNCONSTRAINED = [m for m in METHODS if not INFO[m].adaptive and m not in NONSMOOTH_METHODS
                 and m not in CONSTRAINED_METHODS and not INFO[m].contacts and not INFO[m].nonholonomic]
STEPS = {1: (128, 256, 512, 1024), 2: (32, 64, 128, 256), 4: (128, 256, 512, 1024), 6: (16, 32, 64, 128)}
Q0, V0, T_END = [0.3, 0.8], [0.2, -0.5], 2.0


@pytest.fixture(scope="module")
def forced(time_module):
    return time_module("forced_damped")


def fit(steps, errors):
    return float(np.polyfit(np.log(1.0 / np.asarray(steps)), np.log(errors), 1)[0])


@pytest.mark.parametrize("method", UNCONSTRAINED)
def test_balance_closes_to_the_method_order(forced, method):
    order = INFO[method].order
    errors = []
    for n in STEPS[order]:
        tr = simulate(forced, method, Q0, V0, t_end=T_END, h=T_END / n)
        errors.append(np.abs(tr.energy_balance).max())
    assert tr.max_energy_error > 1.0                # the work is not small: W(2) = 1.645
    slope = fit(STEPS[order], errors)
    print(method, f"balance order {slope:.2f}", errors)
    assert abs(slope - min(order, 4)) < 0.3, (method, slope, errors)


@pytest.fixture(scope="module")
def ring(time_module):
    return time_module("breathing_ring")


@pytest.mark.parametrize("method", ["rattle", "constrained_midpoint"])
def test_balance_on_a_constrained_rheonomic_model(ring, method):
    """The bead on the turning, breathing ring: E changes through the explicit t of L and the
    forcing; the trapezoid quadrature of constrained models is order 2, like the methods."""
    q0, v0 = [math.cos(0.7), math.sin(0.7)], [-math.sin(0.7) * 0.4, math.cos(0.7) * 0.4]
    errors = []
    for n in STEPS[2]:
        tr = simulate(ring, method, q0, v0, t_end=1.0, h=1.0 / n)
        errors.append(np.abs(tr.energy_balance).max())
    assert tr.max_energy_error > 0.1
    slope = fit(STEPS[2], errors)
    assert abs(slope - 2) < 0.3, (method, slope, errors)


def test_work_continues_across_chunks(forced, monkeypatch):
    whole = simulate(forced, "rk4", Q0, V0, t_end=T_END, h=T_END / 200, save_every=10)
    monkeypatch.setattr(fixed_run, "CHUNK_STEPS", 30)
    chunked = simulate(forced, "rk4", Q0, V0, t_end=T_END + 0.005, h=T_END / 200, save_every=10)
    np.testing.assert_allclose(chunked.work[:len(whole.work)], whole.work, rtol=0, atol=1e-13)
    assert len(chunked.t) == len(whole.t) + 1           # the final state is off the saves
    assert abs(chunked.energy_balance[-1]) < 1e-6


def test_conservative_models_carry_no_work(time_module):
    hoop = time_module("rotating_hoop")
    assert not hoop.WORK            # L = T - V has no explicit t: E is conserved
    assert simulate(hoop, "midpoint", [0.3], [0.0], t_end=0.1, h=0.01).work is None


@pytest.mark.parametrize("model, args, line", [
    ("tests/time/models/forced_damped.py", ["--q0", "0.3", "0.8"], "max |E - E0 - W| = "),
    ("models/cart_pendulum.py", ["--q0", "0.3", "0.8"], "max |E - E0| = "),
])
def test_cli_summary_shows_the_balance(tmp_path, model, args, line):
    proc = subprocess.run([sys.executable, "-m", "lagrange_gen.cli", "simulate", str(ROOT / model),
                           "--method", "rk4", "--h", "0.01", "--t-end", "1", *args,
                           "--gen-dir", str(tmp_path)], capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr
    assert line in proc.stdout, proc.stdout
