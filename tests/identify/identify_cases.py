"""Identification test cases (HARD_CASES 10, issue 7): parameters, simulated records, error measure.

The records come from prandtl_reference.simulate_prandtl, an exact implicit Euler simulator written
for these tests only (not the package's steppers), so a bug in the package cannot hide in the data.
The session fixtures live here, not in a conftest.py: the other test directories import
`conftest` by name (tests/conftest.py), and a second conftest module would shadow it. Test files
import the fixtures they use from this module.
"""

import math

import numpy as np
import pytest
from prandtl_reference import simulate_prandtl

# m = 1, c = 0.3, k0 = k_i = 1/3, eta_i = i, F = 4 cos(0.05 t), h = 1e-2.
M, C, K0, K, ETA = 1.0, 0.3, 1 / 3, (1 / 3, 1 / 3, 1 / 3), (1.0, 2.0, 3.0)
OMEGA, H = 0.05, 1e-2
PERIOD = 2 * math.pi / OMEGA


def relative_errors(fit, k0=K0, k=K, eta=ETA):
    """Largest relative error of k0, the k_i and the eta_i of a PrandtlFit."""
    return max(abs(fit.k0 / k0 - 1), np.abs(fit.k / np.array(k) - 1).max(),
               np.abs(fit.eta / np.array(eta) - 1).max())


@pytest.fixture(scope="session")
def prandtl_run():
    """Four forcing periods from rest: a virgin loading, then steady hysteresis cycles."""
    return simulate_prandtl(M, C, K0, K, ETA, lambda t: 4 * math.cos(OMEGA * t), H, 4 * PERIOD)


@pytest.fixture(scope="session")
def weak_run():
    """Forcing amplitude 2.5: the steady cycle unlocks elements 1 and 2 only (see the test)."""
    return simulate_prandtl(M, C, K0, K, ETA, lambda t: 2.5 * math.cos(OMEGA * t), H,
                            3 * PERIOD)


@pytest.fixture(scope="session")
def steady_cycle(prandtl_run):
    """One full steady cycle, maximum to maximum of the forcing: t in [2T, 3T]. Arrays (N,)."""
    r = prandtl_run
    sel = slice(int(round(2 * PERIOD / H)), int(round(3 * PERIOD / H)) + 1)
    return r.t[sel], r.x[sel], r.f_minus_ma[sel], r.v[sel]
