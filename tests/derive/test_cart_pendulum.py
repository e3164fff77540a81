"""The cart pendulum against the hand-derived equations of HARD_CASES case 1 (MEAM 535)."""

import numpy as np
import sympy as sp


def hand_derived(q, qd, p):
    """H (2, 2), h (2,), g (2,) written out by hand."""
    M, m, l, k, g = p
    x, th = q
    xd, thd = qd
    H = np.array([[M + m, m * l * np.cos(th)], [m * l * np.cos(th), m * l**2]])
    h = np.array([-m * l * thd**2 * np.sin(th), 0.0])
    gv = np.array([k * x, m * g * l * np.sin(th)])
    return H, h, gv


def test_symbolic_equations(derived):
    dyn = derived("cart_pendulum")
    x, th = dyn.q
    xd, thd = dyn.qd
    M, m, l, k, g = dyn.params
    H = sp.Matrix([[M + m, m * l * sp.cos(th)], [m * l * sp.cos(th), m * l**2]])
    h = sp.Matrix([-m * l * thd**2 * sp.sin(th), 0])
    gv = sp.Matrix([k * x, m * g * l * sp.sin(th)])
    assert sp.simplify(dyn.H - H) == sp.zeros(2, 2)
    assert sp.simplify(dyn.h - h) == sp.zeros(2, 1)
    assert sp.simplify(dyn.g - gv) == sp.zeros(2, 1)
    assert dyn.Q == sp.zeros(2, 1)


def test_kernels_match_hand_derived_at_random_states(generated):
    mod = generated("cart_pendulum")
    rng = np.random.default_rng(1)
    H = np.empty((2, 2))
    rhs = np.empty(2)
    for _ in range(100):
        q = rng.uniform(-3, 3, 2)
        qd = rng.uniform(-3, 3, 2)
        p = rng.uniform(0.5, 2.0, 5)
        Hh, hh, gh = hand_derived(q, qd, p)
        mod.dynamics(q, qd, 0.0, p, H, rhs)
        np.testing.assert_allclose(H, Hh, rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(rhs, -hh - gh, rtol=1e-12, atol=1e-12)
        qdd = mod.accelerations(q, qd, 0.0, p)
        np.testing.assert_allclose(qdd, np.linalg.solve(Hh, -hh - gh), rtol=1e-12, atol=1e-12)
        # The two scalar equations of motion of HARD_CASES case 1, residuals at round-off.
        M, m, l, k, g = p
        r1 = (M + m) * qdd[0] + m * l * qdd[1] * np.cos(q[1]) - m * l * qd[1] ** 2 * np.sin(q[1]) + k * q[0]
        r2 = m * l**2 * qdd[1] + m * l * qdd[0] * np.cos(q[1]) + m * g * l * np.sin(q[1])
        assert abs(r1) < 1e-11 * (1 + abs(k * q[0]))
        assert abs(r2) < 1e-11 * (1 + m * g * l)
