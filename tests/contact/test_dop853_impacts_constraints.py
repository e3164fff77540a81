"""dop853_impacts on models with holonomic constraints beside contacts: the motion between
switches from the KKT system [[M, -J^T], [J, 0]], the contact forces and impacts on the
constrained motion (core/contact_kkt.py's padded rows), Phi and J v projected at each switch.

References, none of them computed through the constrained model:

* models/slider_crank_stop.py, the same slider-crank in its crank angle alone (the loop closure
  solved in closed form), run by dop853_impacts: the constrained model's crank angle, its impact
  times and, through the crank's equation J th'' = tau + dPhi/dth lam with th'' from the
  one-coordinate model's forward dynamics, its multiplier. Both runs at rtol 1e-10 (atol 1e-12):
  each is accurate to about 1e-9 over a few impacts (the local errors add up over ~100 steps and
  the impact times carry the root finder's error, events.ROOT_RTOL of a step); over 4 s and four
  impacts (measured 1.4e-9 in the angle, 8e-9 in its rate, 2.6e-10 in the impact times, 2.6e-11
  relative in the multiplier). Bounds 1e-7 on the angle, 1e-6 on its rate, 1e-8 on the impact
  times and the multiplier.
* the plastic stop (e = 0): the slider rests at the stop, the crank at the angle th_s of the
  loop closure with x = x_stop, and the torque held by the rod: lam = -tau / dPhi/dth at rest.
* moreau_jean on the constrained model: order 1 towards dop853_impacts' run.
* models/pendulum_wall_cartesian.py: the pendulum in its angle th. Released at rest from th0 it
  reaches the wall (sin th_w = a / l) at t_1 with th'_w (the energy integral and a quadrature,
  scipy's quad); it leaves at -e th'_w, swings out to th_1 (cos th_1 = cos th_w - (e th'_w)^2
  l / (2 g)) and, the swing being time-reversible, comes back to the wall at
  t_2 = t_1 + 2 T(th_1) with rate e th'_w and leaves at -e^2 th'_w (T(th_a) the quarter swing
  from the turning angle th_a to th_w).

|Phi| drift: between switches Phi'' = 0 holds to the integration error, so |Phi| grows by that
(measured up to 4.6e-11 over 4 s of the slider-crank); at each switch q is projected back onto
Phi = 0 and v onto J v = 0 (the rows after a switch: measured 1.1e-16 and 4.4e-16, bounds 1e-13
and 1e-12). The pendulum (measured): impact times 1.4e-11 and 5.6e-11 from the quadratures,
rates 2.1e-10 relative, the rod's tension 2.8e-10, E - E0 - contact_work 2.3e-10.
"""

import math

import numpy as np
import pytest
from scipy.integrate import quad

import lagrange_gen as lg
from lagrange_gen.errors import SimulationError

R, L, J, M, TAU, X_STOP = 0.3, 1.0, 0.05, 1.0, -1.0, 1.25
TH0_CRANK, W0 = math.pi / 2, -1.0
TOL = dict(rtol=1e-10, atol=1e-12)


def _slider(th):
    return R * math.cos(th) + math.sqrt(L**2 - R**2 * math.sin(th)**2)


def _slider_rate(th):
    """dx/dth of the loop closure."""
    return -R * math.sin(th) - R**2 * math.sin(th) * math.cos(th) / math.sqrt(
        L**2 - R**2 * math.sin(th)**2)


def _crank(generated, model, method, e, t_end, **settings):
    params = {"r": R, "L": L, "J": J, "m": M, "tau": TAU, "x_stop": X_STOP, "e": e}
    if model == "slider_crank_stop":
        q0, v0 = [TH0_CRANK], [W0]
    else:
        q0, v0 = [TH0_CRANK, _slider(TH0_CRANK)], [W0, _slider_rate(TH0_CRANK) * W0]
    return lg.simulate(generated(model), method=method, q0=q0, v0=v0, t_end=t_end,
                       params=params, **settings)


def _switch_rows(traj):
    """Rows written after an impact (every-step mode writes the state before and after)."""
    return np.flatnonzero(np.diff(traj.saved["impacts"][:, 0]) > 0) + 1


def test_constrained_slider_crank_bounces_as_the_minimal_one(generated):
    """e = 1 over four impacts: crank angle and rate at common times (dense output), impact
    times, the slider on the loop, the multiplier against the crank's equation."""
    t_end = 4.0
    minimal = _crank(generated, "slider_crank_stop", "dop853_impacts", 1.0, t_end, **TOL)
    constrained = _crank(generated, "slider_crank_stop_constrained", "dop853_impacts", 1.0,
                         t_end, **TOL)
    t_min, t_con = minimal.t[_switch_rows(minimal)], constrained.t[_switch_rows(constrained)]
    assert len(t_min) == 4 and len(t_con) == 4
    assert np.abs(t_min - t_con).max() <= 1e-8
    times = np.linspace(0.0, t_end, 161)
    dense_min = _crank(generated, "slider_crank_stop", "dop853_impacts", 1.0, t_end,
                       t_eval=times, **TOL)
    dense_con = _crank(generated, "slider_crank_stop_constrained", "dop853_impacts", 1.0, t_end,
                       t_eval=times, **TOL)
    assert np.abs(dense_min.q[:, 0] - dense_con.q[:, 0]).max() <= 1e-7
    assert np.abs(dense_min.v[:, 0] - dense_con.v[:, 0]).max() <= 1e-6
    slider = np.array([_slider(th) for th in dense_con.q[:, 0]])
    assert np.abs(dense_con.q[:, 1] - slider).max() <= 1e-8
    # behind the stop but for the located impact (the root finder's error of a step)
    assert constrained.q[:, 1].max() <= X_STOP + 1e-9
    # the multiplier: J th'' = tau + dPhi/dth lam, th'' from the minimal model's dynamics
    minimal_module = generated("slider_crank_stop")
    params = {"r": R, "L": L, "J": J, "m": M, "tau": TAU, "x_stop": X_STOP, "e": 1.0}
    for k in range(0, len(constrained.t), 5):
        th, x = constrained.q[k]
        acc = minimal_module.accelerations([th], [constrained.v[k, 0]], constrained.t[k],
                                           params)[0]
        dphi_dth = (x - R * math.cos(th)) * R * math.sin(th) + R**2 * math.sin(th) * math.cos(th)
        lam = (J * acc - TAU) / dphi_dth
        assert constrained.multipliers[k, 0] == pytest.approx(lam, rel=1e-8)


def test_constraint_drift_is_removed_at_each_switch(generated):
    """|Phi| stays at the integration error between switches and is back at rounding on the
    rows after each impact (the projection), as is J v."""
    traj = _crank(generated, "slider_crank_stop_constrained", "dop853_impacts", 1.0, 4.0, **TOL)
    phi, jv = traj.constraint_error, traj.velocity_constraint_error
    print("max |Phi|", phi.max(), "max |J v|", jv.max())
    assert phi.max() <= 1e-9 and jv.max() <= 1e-8
    after = _switch_rows(traj)
    assert phi[after].max() <= 1e-13 and jv[after].max() <= 1e-12
    # the drift between switches is real (so the check above sees the projection work)
    assert phi[after - 1].max() > phi[after].max()


def test_plastic_stop_holds_the_constrained_slider(generated):
    """e = 0: the slider stops at x_stop and stays there (a persistent contact on the
    constrained motion), the crank at th_s, the rod holding the torque: lam = -tau / dPhi/dth;
    the minimal model reaches the same stop at the same time."""
    minimal = _crank(generated, "slider_crank_stop", "dop853_impacts", 0.0, 1.0, **TOL)
    traj = _crank(generated, "slider_crank_stop_constrained", "dop853_impacts", 0.0, 1.0, **TOL)
    th_s = math.acos((X_STOP**2 + R**2 - L**2) / (2 * X_STOP * R))
    t_min, t_con = minimal.t[_switch_rows(minimal)], traj.t[_switch_rows(traj)]
    assert len(t_con) == 1 and abs(t_con[0] - t_min[0]) <= 1e-8
    after = _switch_rows(traj)[0]
    assert np.abs(traj.v[after:]).max() <= 1e-9
    assert np.abs(traj.q[after:, 0] - th_s).max() <= 1e-8
    assert np.abs(traj.q[after:, 1] - X_STOP).max() <= 1e-9
    assert (traj.saved["contact_mode"][after:, 0] == 1).all()
    dphi_dth = (X_STOP - R * math.cos(th_s)) * R * math.sin(th_s) + R**2 * math.sin(th_s) * \
        math.cos(th_s)
    assert traj.multipliers[-1, 0] == pytest.approx(-TAU / dphi_dth, rel=1e-8)
    assert abs(minimal.q[-1, 0] - th_s) <= 1e-8


def test_moreau_jean_converges_to_it_at_order_one(generated):
    """moreau_jean on the constrained model against dop853_impacts' run (crank angle at the
    steps' times, e = 1 through one impact): the difference at least halves when h is divided by
    four and is below 15 h (measured 1.1e-2 and 2.9e-3 at h = 1e-3, 2.5e-4: the impact located
    within a step, the angle off by about h th' there and the rate's error carried on)."""
    t_end = 1.0
    diffs = []
    for h in (1e-3, 2.5e-4):
        mj = _crank(generated, "slider_crank_stop_constrained", "moreau_jean", 1.0, t_end, h=h,
                    save_every=10)
        ref = _crank(generated, "slider_crank_stop_constrained", "dop853_impacts", 1.0, t_end,
                     t_eval=mj.t[1:], **TOL)
        diffs.append(np.abs(mj.q[1:, 0] - ref.q[:, 0]).max())
    print("moreau_jean - dop853_impacts", diffs)
    assert diffs[0] <= 15 * 1e-3 and diffs[1] <= diffs[0] / 2


G, L_ROD, A_WALL, E = 9.81, 1.0, 0.5, 0.8
TH0 = -0.6
TH_W = math.asin(A_WALL / L_ROD)


def _quarter_swing(th_a):
    """Time from the turning angle th_a (rate 0) to th_w: integral of dth / th'(th), th'^2 =
    2 g (cos th - cos th_a) / l, with th = th_a + (th_w - th_a) sin^2 s (the endpoint's 1/sqrt
    removed)."""
    d = TH_W - th_a

    def integrand(s):
        th = th_a + d * math.sin(s)**2
        return 2 * d * math.sin(s) * math.cos(s) / math.sqrt(
            2 * G * (math.cos(th) - math.cos(th_a)) / L_ROD)
    return quad(integrand, 0.0, math.pi / 2, epsabs=1e-14, epsrel=1e-13)[0]


def test_cartesian_pendulum_bounces_off_the_wall_as_the_angle_form_does(generated):
    rate_w = math.sqrt(2 * G * (math.cos(TH_W) - math.cos(TH0)) / L_ROD)
    t1 = _quarter_swing(TH0)
    th1 = math.acos(math.cos(TH_W) - (E * rate_w)**2 * L_ROD / (2 * G))
    th1 = -th1                                           # it swings back past the bottom
    t2 = t1 + 2 * _quarter_swing(th1)
    traj = lg.simulate(generated("pendulum_wall_cartesian"), method="dop853_impacts",
                       q0=[L_ROD * math.sin(TH0), -L_ROD * math.cos(TH0)], v0=[0.0, 0.0],
                       t_end=t2 + 0.1, params={"g": G, "l": L_ROD, "a": A_WALL, "e": E}, **TOL)
    x, y = traj.q[:, 0], traj.q[:, 1]
    rate = (x * traj.v[:, 1] - y * traj.v[:, 0]) / (x**2 + y**2)
    after = _switch_rows(traj)
    assert len(after) == 2
    assert np.abs(traj.t[after] - [t1, t2]).max() <= 1e-8
    assert np.abs(np.arctan2(x[after], -y[after]) - TH_W).max() <= 1e-8
    assert rate[after[0] - 1] == pytest.approx(rate_w, rel=1e-8)
    assert rate[after[0]] == pytest.approx(-E * rate_w, rel=1e-8)
    assert rate[after[1] - 1] == pytest.approx(E * rate_w, rel=1e-8)
    assert rate[after[1]] == pytest.approx(-E**2 * rate_w, rel=1e-8)
    # the rod's tension (m = 1): lam = -(g cos th + l th'^2) / l, at every row
    th = np.arctan2(x, -y)
    tension = -(G * np.cos(th) + L_ROD * rate**2) / L_ROD
    assert np.abs(traj.multipliers[:, 0] - tension).max() <= 1e-7
    assert traj.constraint_error.max() <= 1e-9
    # E - E0 - contact_work closes (the rod does no work)
    balance = traj.energy - traj.energy[0] - traj.saved["contact_work"][:, 0]
    assert np.abs(balance).max() <= 1e-8


def test_nonholonomic_rows_beside_contacts_stay_refused_in_one_line(generated):
    """dop853_impacts treats holonomic constraints beside contacts, not velocity constraints:
    one line naming the model, the method and the one that does (moreau_jean)."""
    with pytest.raises(SimulationError) as caught:
        lg.simulate(generated("sleigh_drop"), "dop853_impacts", [0.0, 0.0, 1.0, 0.3],
                    [1.0, 0.0, 0.0, 0.0], t_end=0.01)
    message = str(caught.value)
    assert "\n" not in message
    assert "sleigh_drop" in message and "dop853_impacts" in message
    assert "nonholonomic constraints beside contacts (use moreau_jean)" in message


def test_a_run_in_chunks_continues_on_the_constraint(generated, monkeypatch):
    """The driver calls the glue again when its row buffers fill (run/adaptive_driver.py); each
    call starts by classifying the contacts and projecting onto Phi = 0 there, which moves the
    state by the drift alone: with buffers of 4 rows the run ends where one call does, to the
    integration's accuracy (measured 2.3e-12), with the same impacts, on the constraint, and
    every row carries a multiplier (the rod always pushes or pulls here)."""
    from lagrange_gen.run import adaptive_driver
    whole = _crank(generated, "slider_crank_stop_constrained", "dop853_impacts", 1.0, 2.0,
                   **TOL)
    monkeypatch.setattr(adaptive_driver, "FIRST_ROWS", 4)
    monkeypatch.setattr(adaptive_driver, "CHUNK_ROWS", 4)
    chunked = _crank(generated, "slider_crank_stop_constrained", "dop853_impacts", 1.0, 2.0,
                     **TOL)
    assert chunked.saved["impacts"][-1, 0] == whole.saved["impacts"][-1, 0] == 2
    print("chunked - whole", np.abs(chunked.q[-1] - whole.q[-1]).max())
    assert np.abs(chunked.q[-1] - whole.q[-1]).max() <= 1e-8
    assert chunked.constraint_error.max() <= 1e-9
    assert np.isfinite(chunked.multipliers).all() and (chunked.multipliers != 0.0).all()
