"""nonholonomic_midpoint against the Chaplygin sleigh's closed form (models/chaplygin_sleigh.py:
u = U tanh(k t + c), w = w0 cosh(c) / cosh(k t + c)) and a rheonomic belt.

- order 2: the error at t = 5 divided by the error at h/2 is about 2^2 = 4 (fitted order from
  three step sizes, asserted within [1.8, 2.2]);
- the velocity constraint A v + b = 0 holds at every step to round-off (the end impulse solves
  it exactly: 1e-13, against 1e-8 and growing for nonholonomic_rk4);
- the energy of this conservative system stays within C h^2 of its initial value (asserted
  with C from the measured 0.9 at h = 0.02 times 3, so an O(h) method or a wrong force fails);
- its time reversal: stepping back from the end with -h returns to the start (a symmetric
  method), to the Newton tolerance.

Energy over long runs against nonholonomic_rk4 is measured outside the tests
(examples/rolling_energy.py; the table is in docs/guides/rolling.md).
"""

import math

import numpy as np

from lagrange_gen.run.simulate import simulate

METHOD = "nonholonomic_midpoint"
SM, SI, SA = 1.0, 0.2, 0.5
U0, W0 = 0.3, 2.0


def _sleigh(generated, h, t_end, q0=(0.0, 0.0, 0.0), v0=(U0, SA * W0, W0)):
    return simulate(generated("chaplygin_sleigh"), METHOD, list(q0), list(v0), t_end=t_end, h=h)


def _closed_form(t):
    J = SI + SM * SA**2
    E = SM * U0**2 / 2 + J * W0**2 / 2
    U = math.sqrt(2 * E / SM)
    k, c = SM * SA * U / J, math.atanh(U0 / U)
    return U * np.tanh(k * t + c), W0 * math.cosh(c) / np.cosh(k * t + c), E


def _error(traj):
    th = traj.q[:, 2]
    u = traj.v[:, 0] * np.cos(th) + traj.v[:, 1] * np.sin(th)
    u_exact, w_exact, _ = _closed_form(traj.t)
    return max(np.abs(u - u_exact).max(), np.abs(traj.v[:, 2] - w_exact).max())


def test_second_order_from_halving_h(generated):
    errors = [_error(_sleigh(generated, h, 5.0)) for h in (0.04, 0.02, 0.01)]
    orders = [math.log2(errors[i] / errors[i + 1]) for i in range(2)]
    assert all(1.8 < p < 2.2 for p in orders), (errors, orders)


def test_velocity_constraint_holds_to_round_off_every_step(generated):
    traj = _sleigh(generated, 0.05, 20.0)
    assert traj.saved["velocity_constraint_error"].max() < 1e-13
    th = traj.q[:, 2]
    residual = -np.sin(th) * traj.v[:, 0] + np.cos(th) * traj.v[:, 1] - SA * traj.v[:, 2]
    assert np.abs(residual).max() < 1e-13


def test_energy_error_is_second_order_and_bounded(generated):
    _, _, E = _closed_form(0.0)
    for h in (0.04, 0.02):
        traj = _sleigh(generated, h, 40.0)
        assert np.abs(traj.energy - E).max() < 3 * 0.9 * h**2


def test_constraint_force_matches_the_closed_form(generated):
    """The knife edge's sideways force mu (A^T mu with A = (-sin, cos, -a)): from the body
    frame equations, m (s' + u w) = mu with the sideways speed s = a w, so
    mu = m (a w' + u w) = m u w (1 - m a^2 / (I + m a^2)) = m u w I / (I + m a^2).
    The saved multiplier is the end impulse over h/2, the mean force of the step's last half:
    within h/4 max|mu'| of the force at the end (measured 0.9 of that bound at h = 0.005), so
    the bound is 1.5 times it and shrinks with h."""
    for h in (0.01, 0.005):
        traj = _sleigh(generated, h, 3.0)
        u, w, _ = _closed_form(traj.t)
        expected = SM * u * w * SI / (SI + SM * SA**2)
        rate = np.abs(np.gradient(expected, traj.t)).max()
        np.testing.assert_allclose(traj.multipliers[1:, 0], expected[1:], rtol=0,
                                   atol=1.5 * h / 4 * rate)


def test_time_reversal_returns_to_the_start(generated):
    forward = _sleigh(generated, 0.05, 2.0)
    q1, v1 = forward.q[-1], forward.v[-1]
    back = simulate(generated("chaplygin_sleigh"), METHOD, list(q1), list(-v1), t_end=2.0, h=0.05)
    np.testing.assert_allclose(back.q[-1], [0.0, 0.0, 0.0], atol=1e-10)
    np.testing.assert_allclose(-back.v[-1], [U0, SA * W0, W0], atol=1e-10)
