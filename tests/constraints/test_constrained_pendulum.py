"""The Cartesian pendulum (|x| = l as a constraint) against the same pendulum in one angle, and
the long-time energy of rattle on the Cartesian double pendulum."""

import numpy as np
import pytest

from constraint_util import generated_model, one_angle_pendulum, pendulum_state
from lagrange_gen.run.consistent import initial_multipliers
from lagrange_gen.run.simulate import simulate
from lagrange_gen.steppers.core.registry import INFO

THETA0, OMEGA0, T_END = 1.0, 0.5, 1.0
STEPS = {1: (100, 200, 400, 800, 1600), 2: (25, 50, 100, 200, 400)}


@pytest.mark.parametrize("method", ["rattle", "constrained_midpoint", "constrained_implicit_euler"])
def test_cartesian_pendulum_follows_one_angle_pendulum(method):
    """Error at t = 1 against the one-angle pendulum (DOP853, 1e-13) shrinks with the method's
    order (fitted slope within 0.15), and the reported multiplier approaches the exact
    constraint force (lam = KKT multiplier on the reference state)."""
    mod = generated_model("cartesian_pendulum")
    p = np.array(mod.DEFAULTS)
    q0, v0 = pendulum_state(THETA0, OMEGA0)
    theta, omega = one_angle_pendulum(THETA0, OMEGA0, np.array([T_END]))
    q_ref, v_ref = pendulum_state(theta[0], omega[0])
    lam_ref = initial_multipliers(mod, q_ref, v_ref, T_END, p)
    order = INFO[method].order
    hs, errors, lam_errors = [], [], []
    for n in STEPS[order]:
        traj = simulate(mod, method, q0, v0, t_end=T_END, h=T_END / n, save_every=n)
        hs.append(T_END / n)
        errors.append(max(np.abs(traj.q[-1] - q_ref).max(), np.abs(traj.v[-1] - v_ref).max()))
        lam_errors.append(np.abs(traj.multipliers[-1] - lam_ref).max())
        assert traj.constraint_error.max() < 1e-12 and traj.velocity_constraint_error.max() < 1e-12
    slope = np.polyfit(np.log(hs), np.log(errors), 1)[0]
    assert abs(slope - order) <= 0.15, (slope, errors)
    # The reported multipliers converge (at least first order) to the exact force, about -9.
    lam_slope = np.polyfit(np.log(hs), np.log(lam_errors), 1)[0]
    assert lam_slope >= 0.85 and lam_errors[-1] < 0.05 * abs(lam_ref[0]), (lam_slope, lam_errors)


def test_rattle_energy_bounded_on_cartesian_double_pendulum():
    """1e6 rattle steps (h = 1e-3, t = 1000, chaotic motion): the energy error stays bounded at
    O(h^2) with no drift (the last tenth of the run is no worse than the first), and the
    constraints hold at the Newton tolerance throughout."""
    mod = generated_model("cartesian_double_pendulum")
    th1, th2 = 1.0, 2.0
    q0 = np.array([np.sin(th1), -np.cos(th1), np.sin(th1) + np.sin(th2),
                   -np.cos(th1) - np.cos(th2)])
    n_steps, h = 1_000_000, 1e-3
    traj = simulate(mod, "rattle", q0, np.zeros(4), t_end=n_steps * h, h=h, save_every=100)
    err = np.abs(traj.energy_error)
    tenth = len(err) // 10
    assert err.max() < 2e-3 * abs(traj.energy[0]), err.max()
    first, last = err[:tenth].max(), err[-tenth:].max()
    assert last < 1.5 * first + 1e-6, (first, last)
    assert traj.constraint_error.max() < 1e-11
    assert traj.velocity_constraint_error.max() < 1e-11


def test_rattle_newton_path_equals_explicit_path():
    """For constant H the Newton path (generalized RATTLE in (u, w, nu), used for H(q)) is the
    same scheme as the explicit classical RATTLE: equal to the Newton tolerance."""
    mod = generated_model("cartesian_pendulum")
    q0, v0 = pendulum_state(THETA0, OMEGA0)
    fast = simulate(mod, "rattle", q0, v0, t_end=1.0, h=1e-2)
    newton = simulate(mod, "rattle", q0, v0, t_end=1.0, h=1e-2, newton_always=True)
    assert fast.newton_iters.sum() <= 200          # at most two Newton updates per step
    assert np.abs(fast.q - newton.q).max() < 1e-11
    assert np.abs(fast.v - newton.v).max() < 1e-10
