"""explicit_rk's tableau-driven core: with the rk4 tableau it is rk4 (bit for bit against a
hand-written classical RK4 on the generated ``accelerations``), and other tableaux give their own
order (so the core really reads the tableau)."""

import numpy as np
import pytest
from numba import njit

from stepper_util import model, one_step, params  # model is a fixture
from lagrange_gen.steppers.core.explicit_rk import (HEUN_A, HEUN_B, HEUN_C, RK4_A, RK4_B, RK4_C,
                                               RULE38_A, RULE38_B, RULE38_C, rk_step)
from lagrange_gen.steppers.core.status import OK
from lagrange_gen.steppers.methods import rk4

STATES = [([0.3, 0.8], [0.2, -0.5]), ([-1.2, 2.9], [1.5, 3.0]), ([0.0, 0.0], [0.0, 0.0])]


def hand_rk4(mod, q, v, t, h):
    """Classical RK4 on (q, v) written out, weights (1/6, 1/3, 1/3, 1/6) applied to the stages
    in order (the core's summation order, so the result is bit for bit the same)."""
    def acc(qs, vs, ts):
        return mod.accelerations(qs, vs, ts)
    a1 = acc(q, v, t)
    v2 = v + h * (0.5 * a1)
    a2 = acc(q + h * (0.5 * v), v2, t + 0.5 * h)
    v3 = v + h * (0.5 * a2)
    a3 = acc(q + h * (0.5 * v2), v3, t + 0.5 * h)
    v4 = v + h * a3
    a4 = acc(q + h * v3, v4, t + h)
    w1, w2 = 1.0 / 6.0, 1.0 / 3.0
    q_new = q + h * (w1 * v + w2 * v2 + w2 * v3 + w1 * v4)
    v_new = v + h * (w1 * a1 + w2 * a2 + w2 * a3 + w1 * a4)
    return q_new, v_new, (q + h / 6.0 * (v + 2 * v2 + 2 * v3 + v4),
                          v + h / 6.0 * (a1 + 2 * a2 + 2 * a3 + a4))


@pytest.mark.parametrize("q0, v0", STATES)
@pytest.mark.parametrize("h", [0.01, 0.37])
def test_rk4_is_the_core_with_the_rk4_tableau(model, q0, v0, h):
    mod = model("cart_pendulum")
    q0, v0 = np.array(q0), np.array(v0)
    q1, v1 = one_step(mod, "rk4", q0, v0, h, params(mod), t0=0.5)
    q_hand, v_hand, (q_textbook, v_textbook) = hand_rk4(mod, q0, v0, 0.5, h)
    assert np.array_equal(q1, q_hand) and np.array_equal(v1, v_hand), (q1 - q_hand, v1 - v_hand)
    # The h/6 (k1 + 2 k2 + 2 k3 + k4) form of the old rk4.py rounds differently: last bits only.
    assert np.allclose(q1, q_textbook, rtol=1e-15, atol=1e-15)
    assert np.allclose(v1, v_textbook, rtol=1e-15, atol=1e-15)


def integrator(kern):
    """A jitted integrate(A, b, c, q, v, h, n_steps, p) -> status: n_steps steps of the tableau
    with rk4's forward-dynamics callback, (q, v) in place. kern (the generated module) is a
    closure constant: numba cannot take a module as an argument from Python."""
    @njit
    def integrate(A, b, c, q, v, h, n_steps, p):
        n, s = q.shape[0], b.shape[0]
        work = np.zeros((2 * s + 1, n))
        H = np.zeros((n, n))
        for i in range(n_steps):
            status = rk_step(rk4, kern, (p, H), A, b, c, q, v, i * h, h, work[:s],
                             work[s:2 * s], work[2 * s], q, v, False)
            if status != OK:
                return status
        return OK
    return integrate


def damped_exact(x0, v0, b, t):
    """x'' + b x' + x = 0 (m = c = 1, b < 2) in closed form: (x, x') at t."""
    wd = np.sqrt(1.0 - b * b / 4.0)
    A, B = x0, (v0 + 0.5 * b * x0) / wd
    decay = np.exp(-0.5 * b * t)
    cos, sin = np.cos(wd * t), np.sin(wd * t)
    x = decay * (A * cos + B * sin)
    dx = -0.5 * b * x + decay * wd * (-A * sin + B * cos)
    return x, dx


@pytest.mark.parametrize("tableau, order", [((HEUN_A, HEUN_B, HEUN_C), 2),
                                            ((RULE38_A, RULE38_B, RULE38_C), 4),
                                            ((RK4_A, RK4_B, RK4_C), 4)])
def test_fitted_order_of_a_tableau(generated, tableau, order):
    mod = generated("damped_oscillator")
    damping, t_end = 0.3, 2.0
    p = params(mod, b=damping)
    x_ref, v_ref = damped_exact(0.7, -0.4, damping, t_end)
    integrate = integrator(mod)
    hs, errors = [], []
    for n in (16, 32, 64, 128, 256):
        q, v = np.array([0.7]), np.array([-0.4])
        assert integrate(*tableau, q, v, t_end / n, n, p) == OK
        hs.append(t_end / n)
        errors.append(max(abs(q[0] - x_ref), abs(v[0] - v_ref)))
    slope = np.polyfit(np.log(hs), np.log(errors), 1)[0]
    assert abs(slope - order) <= 0.15, (slope, errors)


def test_tableaux_are_consistent():
    """c_i = sum_j A_ij, A strictly lower triangular, sum b = 1."""
    for A, b, c in ((HEUN_A, HEUN_B, HEUN_C), (RULE38_A, RULE38_B, RULE38_C),
                    (RK4_A, RK4_B, RK4_C)):
        assert np.array_equal(np.triu(A), np.zeros_like(A))
        assert np.allclose(A.sum(axis=1), c, rtol=0, atol=1e-15)
        assert abs(b.sum() - 1.0) <= 1e-15
