"""The work W in adaptive runs (dop853, steppers/methods/dop853.py): W' = P(q, v, t) stepped
with q, v by the same tableau, under the same error control, with the same dense output, so
that E - E0 - W closes at the tolerance.

Checks: the damped oscillator against the closed form of E(t) (W = E(t) - E0 exactly, at the
step ends and from the dense output between them); one step of size h on the forced, damped
pendulum on a sprung cart, against scipy's quad of the power P written here by hand along a
tight scipy DOP853 solution: the end value's error falls like h^9 (local order 8), the dense
output's at mid-step like h^8 (order 7); over a run the balance error and the error of W both
shrink in proportion to rtol (the tolerance proportionality of dop853's positions); the cart
pole with viscous friction and a constant push; W continued across the driver's chunks is
the W of one call, bit for bit."""

import math

import numpy as np
import pytest
from scipy.integrate import quad, solve_ivp

from lagrange_gen import simulate
from lagrange_gen.run import adaptive_driver
from time_util import generated_rhs

# forced_damped's defaults (tests/time/models/forced_damped.py)
C_X, D_TH, F, NU = 0.3, 0.1, 2.0, 3.0
Q0, V0 = [0.3, 0.8], [0.2, -0.5]


@pytest.fixture(scope="module")
def forced(time_module):
    return time_module("forced_damped")


@pytest.fixture(scope="module")
def damped(time_module):
    return time_module("damped_oscillator")


def forced_power(t, y):
    """P = x' (F cos(nu t) - c x') - d theta'^2: the forcing's and the dampers' power, from the
    model file's forces and dissipation (not through derive/)."""
    xd, thd = y[2], y[3]
    return xd * (F * math.cos(NU * t) - C_X * xd) - D_TH * thd**2


def reference_work(mod, power, q0, v0, times):
    """W at ``times`` by quad of power(t, y(t)) along scipy's DOP853 at 1e-13 (dense output),
    a piece per interval between consecutive times."""
    p = np.array(mod.DEFAULTS, float)
    sol = solve_ivp(generated_rhs(mod, p), (0.0, times[-1]), np.r_[q0, v0], method="DOP853",
                    rtol=1e-13, atol=1e-13, dense_output=True)
    assert sol.success
    edges = np.r_[0.0, times]
    pieces = [quad(lambda s: power(s, sol.sol(s)), a, b, epsabs=1e-14, epsrel=1e-13,
                   limit=200)[0] for a, b in zip(edges[:-1], edges[1:])]
    return np.cumsum(pieces)


def test_damped_oscillator_work_is_the_closed_form_energy_loss(damped):
    """m x'' + b x' + x / c = 0 from x = 1 at rest: x = e^(-g t) (cos w t + g / w sin w t),
    g = b / 2m, w = sqrt(1 / (m c) - g^2); W(t) = E(t) - E0 with E = m x'^2 / 2 + x^2 / 2c."""
    b = 0.5
    gam, w = b / 2, math.sqrt(1.0 - (b / 2)**2)

    def exact_loss(t):
        x = np.exp(-gam * t) * (np.cos(w * t) + gam / w * np.sin(w * t))
        v = -np.exp(-gam * t) * (w + gam**2 / w) * np.sin(w * t)
        return 0.5 * v**2 + 0.5 * x**2 - 0.5

    steps = simulate(damped, "dop853", [1.0], t_end=10.0, params={"b": b}, rtol=1e-10,
                     atol=1e-12)
    t_eval = np.linspace(0.05, 10.0, 200)      # mostly between the steps: the dense output
    between = simulate(damped, "dop853", [1.0], t_end=10.0, params={"b": b}, rtol=1e-10,
                       atol=1e-12, t_eval=t_eval)
    assert steps.work[-1] < -0.49              # the dampers took almost all of E0 = 1/2
    for traj in (steps, between):
        assert np.abs(traj.work - exact_loss(traj.t)).max() < 1e-10
        assert traj.max_energy_balance_error < 1e-10
    inside = ~np.isin(between.t, steps.t)
    assert inside.sum() > 150


def test_one_step_orders_of_w_and_of_its_dense_output(forced):
    """Every step accepted (rtol = atol = 1e6), h_max = h: W at h falls like h^9 (local error of
    order 8), W at h / 2 from the dense output like h^8 (order 7)."""
    hs = np.array([0.4, 0.2, 0.1])
    end_err, mid_err = [], []
    for h in hs:
        traj = simulate(forced, "dop853", Q0, V0, t_end=h, h=h, h_max=h, rtol=1e6, atol=1e6,
                        t_eval=[h / 2, h])
        assert traj.step_counts["accepted"] == 1
        ref = reference_work(forced, forced_power, Q0, V0, [h / 2, h])
        mid_err.append(abs(traj.work[0] - ref[0]))
        end_err.append(abs(traj.work[1] - ref[1]))
    end_slope = np.polyfit(np.log(hs), np.log(end_err), 1)[0]
    mid_slope = np.polyfit(np.log(hs), np.log(mid_err), 1)[0]
    print("W one step: end", end_err, end_slope, "mid", mid_err, mid_slope)
    assert 8.3 < end_slope < 11.0, (end_err, end_slope)
    assert 7.3 < mid_slope < 11.0, (mid_err, mid_slope)


def test_balance_and_work_errors_shrink_in_proportion_to_rtol(forced):
    """rtol = atol from 1e-5 to 1e-10 over t in [0, 4]: max |E - E0 - W| and |W(4) - W_quad(4)|
    fitted against rtol, slope about 1 (dop853's tolerance proportionality)."""
    tols = 10.0 ** -np.arange(5, 11)
    t_end = 4.0
    w_ref = reference_work(forced, forced_power, Q0, V0, np.linspace(0.5, t_end, 8))[-1]
    balance, work = [], []
    for tol in tols:
        traj = simulate(forced, "dop853", Q0, V0, t_end=t_end, rtol=tol, atol=tol)
        balance.append(traj.max_energy_balance_error)
        work.append(abs(traj.work[-1] - w_ref))
        assert traj.max_energy_error > 1.0          # E - E0 is not small: the work matters
    balance_slope = np.polyfit(np.log(tols), np.log(balance), 1)[0]
    work_slope = np.polyfit(np.log(tols), np.log(work), 1)[0]
    print("balance", balance, balance_slope, "W", work, work_slope)
    assert 0.75 < balance_slope < 1.25, (balance, balance_slope)
    assert 0.75 < work_slope < 1.25, (work, work_slope)
    assert max(balance[-1], work[-1]) < 1e-8


def test_cart_pole_with_friction_and_a_push(time_module):
    """The cart pole (models/cart_pole.py) with viscous friction c on the cart and a constant
    push u: P = x' (u - c x'), W against quad along the reference at t_eval."""
    mod = time_module("cart_pole")
    u, c = 0.7, 0.4
    params = {"u": u, "c": c}
    names = list(mod.PARAMS)
    times = np.linspace(0.25, 3.0, 12)
    traj = simulate(mod, "dop853", [0.0, 0.3], [0.0, 0.0], t_end=3.0, params=params,
                    rtol=1e-11, atol=1e-12, t_eval=times)
    p = np.array(mod.DEFAULTS, float)
    p[names.index("u")], p[names.index("c")] = u, c
    sol = solve_ivp(generated_rhs(mod, p), (0.0, 3.0), [0.0, 0.3, 0.0, 0.0], method="DOP853",
                    rtol=1e-13, atol=1e-13, dense_output=True)
    edges = np.r_[0.0, times]
    ref = np.cumsum([quad(lambda s: sol.sol(s)[2] * (u - c * sol.sol(s)[2]), a, b,
                          epsabs=1e-15, epsrel=1e-14, limit=200)[0]
                     for a, b in zip(edges[:-1], edges[1:])])
    assert abs(ref[-1]) > 0.1
    assert np.abs(traj.work - ref).max() < 1e-9
    assert traj.max_energy_balance_error < 1e-9


def test_work_continues_across_the_drivers_chunks(forced, monkeypatch):
    whole = simulate(forced, "dop853", Q0, V0, t_end=3.0, rtol=1e-9, atol=1e-9)
    monkeypatch.setattr(adaptive_driver, "FIRST_ROWS", 4)
    monkeypatch.setattr(adaptive_driver, "CHUNK_ROWS", 8)
    chunked = simulate(forced, "dop853", Q0, V0, t_end=3.0, rtol=1e-9, atol=1e-9)
    assert len(whole.t) > 40                        # several calls of the glue
    np.testing.assert_array_equal(chunked.t, whole.t)
    np.testing.assert_array_equal(chunked.work, whole.work)
    assert whole.max_energy_balance_error < 1e-7
