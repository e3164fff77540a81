"""Jacobians of one discrete step (state and input) against central differences of the
steppers' own steps, at a moving state with a nonzero input."""

import re

import numpy as np
import pytest

import lagrange_gen as lg
from control_util import modulated_pendulum, torque_pendulum  # noqa: F401  (fixtures)
from lagrange_gen.linear.step_derivatives import METHODS
from lagrange_gen.steppers.core.registry import INFO

def _check_against_differences(module, method, t):
    """Newton at 1e-15 (on the methods that have the setting) so the differences of the steps
    (eps = 1e-6) are not dominated by the Newton tolerance."""
    settings = dict(newton_tol=1e-15) if "newton_tol" in INFO[method].setting_names() else {}
    q, v, u, h = np.array([0.3, 0.9]), np.array([-0.4, 1.1]), 0.7, 0.05
    q1, v1, Fx, Gu = lg.step_jacobian(module, method, h, q, v, u=[u], t=t, **settings)

    def step(z):
        a, b, _, _ = lg.step_jacobian(module, method, h, z[:2], z[2:4], u=[z[4]], t=t, **settings)
        return np.concatenate((a, b))

    z, eps = np.concatenate((q, v, [u])), 1e-6
    J = np.array([(step(z + eps * e) - step(z - eps * e)) / (2 * eps) for e in np.eye(5)]).T
    np.testing.assert_allclose(np.concatenate((q1, v1)), step(z), rtol=0, atol=0)
    np.testing.assert_allclose(Fx, J[:, :4], rtol=0, atol=1e-8)
    np.testing.assert_allclose(Gu, J[:, 4:], rtol=0, atol=1e-8)
    assert np.abs(Fx - np.eye(4)).max() > 1e-2       # not the identity: the test can fail


@pytest.mark.parametrize("method", METHODS)
def test_step_jacobian_matches_finite_differences(torque_pendulum, method):
    """H(q) is not constant and the torque u cos(x) depends on the state: every term of the
    implicit-function-theorem formulas is exercised."""
    _check_against_differences(torque_pendulum, method, t=0.0)


@pytest.mark.parametrize("method", METHODS)
def test_step_jacobian_with_time_dependent_inertia(modulated_pendulum, method):
    """H(q, t) at a start t = 0.4: each kernel must be evaluated at the time the step evaluates
    it (the final v1 = H(q1, t + h)^-1 p1 was once taken at t = 0, off by 0.48 in Fx)."""
    _check_against_differences(modulated_pendulum, method, t=0.4)


def test_step_jacobian_refuses_uncovered_method(torque_pendulum):
    covered = re.escape(f"(covered: {', '.join(METHODS)})")
    with pytest.raises(lg.SimulationError, match=f"'dop853' is not covered {covered}"):
        lg.step_jacobian(torque_pendulum, "dop853", 0.01, [0, 0], [0, 0], u=[0.0])
