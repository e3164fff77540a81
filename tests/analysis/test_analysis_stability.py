"""Step matrices measured by lagrange_gen.analysis.stability through ``simulate`` (the path the
bench and case 3 use), against matrices derived by hand, and case 3's verdict."""

import numpy as np
import pytest

from lagrange_gen.analysis import hard_cases, stability
from lagrange_gen.steppers.methods.verlet import linear_step_matrix


@pytest.fixture(scope="module")
def oscillator(generated):
    return generated("damped_oscillator")


def test_explicit_euler_step_matrix_is_the_hand_derived_one(oscillator):
    """x1 = x + h v, v1 = v - h omega^2 x: A = [[1, h], [-h omega^2, 1]]."""
    w = stability.OMEGA
    for tau in (0.1, 1.0, 10.0):
        h = tau / w
        np.testing.assert_allclose(stability.step_matrix(oscillator, "explicit_euler", tau),
                                   [[1.0, h], [-h * w**2, 1.0]], rtol=1e-13, atol=1e-15)


def test_verlet_matrix_closed_form_is_one_measured_step(oscillator):
    """verlet's closed-form step matrix is in the state (x, v / omega): A measured on (x, v)
    maps to it by
    D A D^-1, D = diag(1, 1 / omega)."""
    w = stability.OMEGA
    scale = np.diag([1.0, 1.0 / w])
    for tau in (0.3, 1.9, 2.5):
        measured = stability.step_matrix(oscillator, "verlet", tau)
        np.testing.assert_allclose(scale @ measured @ np.linalg.inv(scale),
                                   linear_step_matrix(tau), rtol=1e-12, atol=1e-13)


def test_case3_verdict_passes_and_lists_every_tau(oscillator):
    result = hard_cases.case3_tau(oscillator, ["verlet", "midpoint"])
    assert result.verdict == hard_cases.PASS
    assert len(result.rows) == 2 * len(stability.TAUS)
    assert all(row[-1] == hard_cases.PASS for row in result.rows)


def test_stability_limit_is_the_last_stable_grid_point():
    taus = np.array([0.5, 1.0, 2.0, 4.0])
    assert stability.stability_limit(taus, np.array([1.0, 1.0, 1.5, 3.0])) == 1.0
    assert stability.stability_limit(taus, np.ones(4)) == np.inf
    assert stability.stability_limit(taus, np.array([1.2, 1.0, 1.0, 1.0])) == 0.0
