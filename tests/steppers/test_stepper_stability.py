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
