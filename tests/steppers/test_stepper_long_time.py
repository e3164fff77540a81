"""Long-time behaviour: bounded energy error of the symplectic methods over 10^6 steps, and the
pendulum near its separatrix against the exact elliptic-function solution (HARD_CASES case 6)."""

import math

import numpy as np
import pytest
from scipy.special import ellipj, ellipk

from stepper_util import model, params, run  # model is a fixture


def energy_error_tenths(mod, method, q0, v0, h, n_steps):
    """(max |E - E0| over the first tenth, over the last tenth) of the run."""
    _, _, _, stats = run(mod, method, np.array(q0), np.array(v0), h, n_steps, params(mod),
                         save_every=100)
    dE = np.abs(stats[:, 0] - stats[0, 0])
    k = len(dE) // 10
    return dE[1:k].max(), dE[-k:].max()


@pytest.mark.parametrize("method", ["verlet", "midpoint"])
def test_energy_error_stays_bounded_over_a_million_steps(model, method):
    first, last = energy_error_tenths(model("double_pendulum"), method, [0.7, -0.4], [0.9, 1.3],
                                      1e-3, 1_000_000)
    assert 0 < first < 1e-3
    assert last <= 2 * first


def test_explicit_euler_energy_grows(model):
    first, last = energy_error_tenths(model("double_pendulum"), "explicit_euler", [0.7, -0.4],
                                      [0.9, 1.3], 1e-3, 1_000_000)
    assert last > 5 * first


# Pendulum theta'' = -sin(theta), theta(0) = 0, theta'(0) = 2k: sin(theta/2) = k sn(t, k^2).
K_SEP = 0.999
PERIOD = 4 * ellipk(K_SEP**2)


def separatrix_run(mod, method, h, periods=2):
    n = int(round(periods * PERIOD / h))
    t, q, v, stats = run(mod, method, [0.0], [2 * K_SEP], h, n, params(mod), save_every=10)
    sn, _, _, _ = ellipj(t, K_SEP**2)
    exact = 2 * np.arcsin(K_SEP * sn)
    return np.abs(q[:, 0] - exact).max(), np.abs(q[:, 0]).max()


# Largest error over two periods at h = 1e-2 and 1e-3 (measured values times about 3).
SEPARATRIX_BOUNDS = {"midpoint": (0.1, 1e-3), "verlet": (0.2, 2e-3), "rk4": (6e-7, 4e-11),
                     "composition": (8e-6, 8e-10)}
ORDERS = {"midpoint": 2, "verlet": 2, "rk4": 4, "composition": 4}


@pytest.mark.parametrize("method", sorted(SEPARATRIX_BOUNDS))
def test_separatrix_pendulum_matches_elliptic_solution(model, method):
    mod = model("pendulum")
    coarse, top = separatrix_run(mod, method, 1e-2)
    fine, _ = separatrix_run(mod, method, 1e-3)
    bound_coarse, bound_fine = SEPARATRIX_BOUNDS[method]
    assert coarse < bound_coarse and fine < bound_fine, (coarse, fine)
    # the error falls as h^order (10x smaller h), rk4's fine error is near round-off
    assert coarse / fine > 0.3 * 10 ** min(ORDERS[method], 3)
    assert top < math.pi                     # never over the top


def test_explicit_euler_crosses_the_separatrix(model):
    _, top = separatrix_run(model("pendulum"), "explicit_euler", 1e-3)
    assert top > math.pi
