"""The spherical pendulum (HARD_CASES case 2) and its coordinate singularity."""

import numpy as np
import pytest
import sympy as sp

from lagrange_gen import SingularMass


def test_symbolic_equations(derived):
    dyn = derived("spherical_pendulum")
    q1, q2 = dyn.q
    q1d, q2d = dyn.qd
    m, l, g = dyn.params
    assert sp.simplify(dyn.H - sp.diag(m * l**2, m * l**2 * sp.sin(q1) ** 2)) == sp.zeros(2, 2)
    # m l^2 q1'' - m l^2 cos q1 sin q1 q2'^2 - m g l sin q1 = 0 and d/dt(m l^2 sin^2 q1 q2') = 0.
    h = sp.Matrix([-m * l**2 * sp.cos(q1) * sp.sin(q1) * q2d**2,
                   2 * m * l**2 * sp.sin(q1) * sp.cos(q1) * q1d * q2d])
    gv = sp.Matrix([-m * g * l * sp.sin(q1), 0])
    assert sp.simplify(dyn.h - h) == sp.zeros(2, 1)
    assert sp.simplify(dyn.g - gv) == sp.zeros(2, 1)


def test_accelerations_match_hand_derived(generated):
    mod = generated("spherical_pendulum")
    rng = np.random.default_rng(2)
    for _ in range(100):
        q = np.array([rng.uniform(0.2, np.pi - 0.2), rng.uniform(-3, 3)])
        qd = rng.uniform(-2, 2, 2)
        m, l, g = p = rng.uniform(0.5, 2.0, 3)
        s, c = np.sin(q[0]), np.cos(q[0])
        q1dd = c * s * qd[1] ** 2 + g / l * s
        q2dd = -2 * c / s * qd[0] * qd[1]
        np.testing.assert_allclose(mod.accelerations(q, qd, 0.0, p), [q1dd, q2dd], rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("q1", [0.0, np.pi])
def test_singular_mass_is_reported_not_nan(generated, q1):
    mod = generated("spherical_pendulum")
    with pytest.raises(SingularMass, match="singular mass matrix"):
        mod.accelerations([q1, 0.3], [0.1, 0.2])
    # The jitted kernel itself returns a status instead of NaNs.
    H, qdd = np.empty((2, 2)), np.empty(2)
    status = mod.forward_dynamics(np.array([q1, 0.3]), np.array([0.1, 0.2]), 0.0, mod.DEFAULT_PARAMS, H, qdd)
    assert status != 0
