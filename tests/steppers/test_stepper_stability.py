"""Linear stability measured from the real steppers (HARD_CASES case 3, DESIGN.md section 6).

One step of each method is applied to the basis vectors (q, v) = (1, 0), (0, 1) of the
oscillator x'' = -omega^2 x; the columns form the step matrix, whose eigenvalues are compared
with the closed forms at tau = h omega.
"""

import math

import numpy as np
import pytest

from stepper_util import model, one_step, params  # model is a fixture
from lagrange_gen.analysis.stability import CLOSED_FORMS, spectral_radius  # closed forms of case 3
from lagrange_gen.steppers.core import registry

TAUS = (0.1, 1.0, 1.9, 1.99, 2.01, 10.0, 1000.0)
OMEGA = 3.0        # not 1, so that h and tau differ and a wrong scaling shows


def step_matrix(mod, method, tau, settings=None):
    p = params(mod, m=1.0, k=OMEGA**2)
    h = tau / OMEGA
    cols = [np.concatenate(one_step(mod, method, [q], [v], h, p, settings=settings))
            for q, v in ((1.0, 0.0), (0.0, 1.0))]
    return np.column_stack(cols)


@pytest.mark.parametrize("method", sorted(CLOSED_FORMS))
def test_spectral_radius_matches_closed_form(model, method):
    mod = model("oscillator")
    for tau in TAUS:
        rho = spectral_radius(step_matrix(mod, method, tau))
        expected = CLOSED_FORMS[method](tau)
        assert rho == pytest.approx(expected, rel=1e-10, abs=1e-12), (method, tau)


def test_verlet_stable_below_two_unstable_above(model):
    mod = model("oscillator")
    for tau in TAUS:
        rho = spectral_radius(step_matrix(mod, "verlet", tau))
        if tau < 2:
            assert abs(rho - 1.0) < 1e-10, tau
        else:
            assert rho > 1.0 + 1e-3, tau


def test_midpoint_phase_is_two_atan_half_tau(model):
    mod = model("oscillator")
    for tau in TAUS:
        eig = np.linalg.eigvals(step_matrix(mod, "midpoint", tau))
        assert np.max(np.abs(np.abs(eig) - 1.0)) < 1e-10, tau
        assert np.max(np.abs(np.angle(eig))) == pytest.approx(2 * math.atan(tau / 2), rel=1e-10)


def test_composition_stability_interval_is_shorter_than_verlets(model):
    """Yoshida 4 is stable (rho = 1) only for tau < 1.573: the substeps g1 h, g2 h are longer
    than h."""
    mod = model("oscillator")
    for tau, stable in ((1.0, True), (1.57, True), (1.58, False), (1.9, False)):
        rho = spectral_radius(step_matrix(mod, "composition", tau))
        assert (abs(rho - 1.0) < 1e-10) == stable, (tau, rho)


@pytest.mark.parametrize("method", ["verlet", "symplectic_euler"])
def test_newton_path_equals_explicit_path_on_linear_system(model, method):
    """Constant H and velocity-free forces: the explicit path and the Newton path are the same
    scheme (the implicit equations are linear), so their step matrices agree."""
    mod = model("oscillator")
    assert mod.MASS_IS_CONSTANT and mod.FORCES_VELOCITY_FREE
    for tau in (0.1, 1.0, 1.9):
        explicit = step_matrix(mod, method, tau)
        newton = step_matrix(mod, method, tau, settings={"newton_always": True})
        np.testing.assert_allclose(newton, explicit, rtol=1e-12, atol=1e-14)


# Kahan-Li p6 s9 (GNI sec. V.3.2), typed here from the paper, not read from composition6.py.
KAHAN_LI_HALF = (0.39216144400731413927925056, 0.33259913678935943859974864,
                 -0.70624617255763935980996482, 0.08221359629355080023149045,
                 0.79854399093482996339895035)


def verlet_matrix(tau):
    """Velocity Verlet on x'' = -x: v* = v - tau/2 x, x+ = x + tau v*, v+ = v* - tau/2 x+."""
    return np.array([[1 - tau**2 / 2, tau], [-tau * (1 - tau**2 / 4), 1 - tau**2 / 2]])


def composition_matrix(half, tau):
    """Product of velocity Verlet matrices (omega = 1) at g tau for the palindromic coefficients
    (g_1, ..., g_k, ..., g_1) given by their first half ``half`` (middle one last)."""
    product = np.eye(2)
    for g in half + half[-2::-1]:
        product = verlet_matrix(g * tau) @ product
    return product


def first_unstable_tau(half, top=4.0):
    """End of the stability interval of the composition: the step matrix has determinant 1, so
    rho = 1 while |trace / 2| <= 1. Scanned on a grid of 1e-4, then bisected."""
    def stable(tau):
        return abs(np.trace(composition_matrix(half, tau)) / 2) <= 1.0
    grid = np.arange(1, int(top * 1e4)) * 1e-4
    lo, hi = next((a, b) for a, b in zip(grid, grid[1:]) if not stable(b))
    for _ in range(50):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if stable(mid) else (lo, mid)
    return lo


def test_composition6_stability_limit_matches_its_derived_value(model):
    """The step matrix of composition6 is the product of its nine Verlet matrices (checked at
    several tau, up to round-off), rho = 1 exactly below the derived limit 2.5326 and > 1 above,
    and its SPEC quotes that limit (stable_tau) and that rho."""
    mod = model("oscillator")
    limit = first_unstable_tau(KAHAN_LI_HALF)
    assert limit == pytest.approx(2.532627, abs=2e-6)
    spec = registry.spec("composition6")
    assert spec.stable_tau <= limit < spec.stable_tau + 1e-4
    for tau in (0.1, 1.0, 2.0, 2.52, 2.55, 2.7):
        measured = step_matrix(mod, "composition6", tau)
        # (x, v) -> (x, v / omega) is the frame of verlet_matrix (omega = 1)
        scaled = np.diag([1.0, 1.0 / OMEGA]) @ measured @ np.diag([1.0, OMEGA])
        np.testing.assert_allclose(scaled, composition_matrix(KAHAN_LI_HALF, tau),
                                   rtol=1e-9, atol=1e-12)
        rho = spectral_radius(measured)
        assert (abs(rho - 1.0) < 1e-10) == (tau < limit), (tau, rho)
        assert rho == pytest.approx(spec.rho(tau), rel=1e-9)
