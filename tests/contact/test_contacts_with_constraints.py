"""Contacts together with holonomic constraints (moreau_jean and spook_contacts: the constraints
are rows of the step's KKT system, core/contact_kkt.py), against closed forms of the same
mechanisms in minimal coordinates.

* models/pendulum_wall_cartesian.py: a pendulum in (x, y) on a rod (x^2 + y^2 = l^2) swinging
  into the wall x = a. In its angle th (x = l sin th) it meets the wall at sin th_w = a / l with
  th'_w^2 = 2 g (cos th_w - cos th0) / l after t_w = integral of dth / th'(th) from th0 (written
  here directly, scipy's quad), and Newton's law on the gap a - x gives th'+ = -e th'_w.
* models/slider_crank_stop_constrained.py: the slider-crank of models/slider_crank_stop.py with
  the slider position a coordinate and the loop closure a constraint; its crank angle must
  follow the minimal-coordinate model's (moreau_jean there) to first order in h.

Tolerances: both methods are order 1 and locate an impact within the step where the free motion
would close the gap, so the impact time is off by about h, the angle there by about h th'_w,
and the rates sampled at the step before and after the impact by about h times the angular
acceleration (g sin th_w / l = 4.9 / s^2 here) for each of the two steps: bounds 2 h, 2 h th'_w
and 4 h g / l (measured at h = 1e-3: 1.4e-3, 1.5e-3, 1.4e-2). The errors at h / 4 must be at
most half those at h (order 1). The constraint is held to O(h^2) (measured 3e-6 at h = 1e-3).
"""

import math

import numpy as np
import pytest
from scipy.integrate import quad

from lagrange_gen import SimulationError
from lagrange_gen.run.simulate import simulate

G, L_ROD, A_WALL, E = 9.81, 1.0, 0.5, 0.8
TH0 = -0.6
TH_W = math.asin(A_WALL / L_ROD)
RATE_W = math.sqrt(2 * G * (math.cos(TH_W) - math.cos(TH0)) / L_ROD)
T_W = quad(lambda th: 1.0 / math.sqrt(2 * G * (math.cos(th) - math.cos(TH0)) / L_ROD),
           TH0, TH_W, epsabs=1e-13, epsrel=1e-12)[0]
METHODS = ("moreau_jean", "spook_contacts")


def _pendulum(generated, method, h, t_end=1.2):
    traj = simulate(generated("pendulum_wall_cartesian"), method=method,
                    q0=[L_ROD * math.sin(TH0), -L_ROD * math.cos(TH0)], v0=[0.0, 0.0],
                    t_end=t_end, h=h, params={"g": G, "l": L_ROD, "a": A_WALL, "e": E})
    x, y = traj.q[:, 0], traj.q[:, 1]
    angle = np.arctan2(x, -y)
    rate = (x * traj.v[:, 1] - y * traj.v[:, 0]) / (x**2 + y**2)
    return traj, angle, rate


def _pendulum_errors(generated, method, h):
    traj, angle, rate = _pendulum(generated, method, h)
    k = np.flatnonzero(traj.saved["normal_impulse"][:, 0] > 0)[0]
    return traj, np.array([abs(traj.t[k] - T_W), abs(angle[k] - TH_W),
                           abs(rate[k - 1] - RATE_W), abs(rate[k] + E * RATE_W)])


@pytest.mark.parametrize("method", METHODS)
def test_cartesian_pendulum_hits_the_wall_as_the_angle_form_does(generated, method):
    h = 1e-3
    traj, errors = _pendulum_errors(generated, method, h)
    bounds = np.array([2 * h, 2 * h * RATE_W, 4 * h * G / L_ROD, 4 * h * G / L_ROD])
    assert (errors <= bounds).all(), errors / bounds
    _, finer = _pendulum_errors(generated, method, h / 4)
    assert (finer <= errors / 2).all(), finer / errors
    assert traj.constraint_error.max() <= 10 * h * h
    # the wall is crossed by the impact step's motion at most: h th'_w
    assert traj.saved["min_gap"].min() >= -h * RATE_W
    # the rod's tension just before the impact: H qdd = rhs + J^T lam with J = (x, y), so
    # lam = -(m g cos th + m l th'^2) / l at the angle th (m = 1; measured 3.8e-3 relative)
    k = np.flatnonzero(traj.saved["normal_impulse"][:, 0] > 0)[0]
    tension = -(G * math.cos(TH_W) + L_ROD * RATE_W**2) / L_ROD
    assert traj.multipliers[k - 1, 0] == pytest.approx(tension, abs=10 * h * abs(tension))
    assert traj.multipliers[0, 0] == pytest.approx(-G * math.cos(TH0) / L_ROD, rel=1e-9)


def test_a_contact_method_needs_the_rows_for_both(generated):
    """Every contact method takes holonomic constraints beside its contacts (dop853_impacts:
    tests/contact/test_dop853_impacts_constraints.py); a constrained method does not take
    contacts."""
    with pytest.raises(SimulationError, match=r"rattle.*ignores the model's unilateral contacts "
                                              r"\(use moreau_jean, spook_contacts, "
                                              r"dop853_impacts\)"):
        simulate(generated("pendulum_wall_cartesian"), method="rattle", q0=[0.0, -1.0],
                 t_end=0.01, h=1e-3)


R, L, J, M, TAU, X_STOP = 0.3, 1.0, 0.05, 1.0, -1.0, 1.25
TH0_CRANK, W0 = math.pi / 2, -1.0


def _slider(th):
    return R * math.cos(th) + math.sqrt(L**2 - R**2 * math.sin(th)**2)


def _slider_rate(th):
    return -R * math.sin(th) - R**2 * math.sin(th) * math.cos(th) / math.sqrt(
        L**2 - R**2 * math.sin(th)**2)


def _crank(generated, model, method, h, e, t_end=1.0):
    params = {"r": R, "L": L, "J": J, "m": M, "tau": TAU, "x_stop": X_STOP, "e": e}
    if model == "slider_crank_stop":
        q0, v0 = [TH0_CRANK], [W0]
    else:
        q0, v0 = [TH0_CRANK, _slider(TH0_CRANK)], [W0, _slider_rate(TH0_CRANK) * W0]
    return simulate(generated(model), method=method, q0=q0, v0=v0, t_end=t_end, h=h,
                    params=params)


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("e", [0.0, 1.0])
def test_constrained_slider_crank_follows_the_minimal_one(generated, method, e):
    """The crank angle of the constrained model against the one-coordinate model's (moreau_jean)
    over a run with the stop: the difference shrinks at least by half when h does by four
    (measured 2.3e-4 -> 4.8e-5 (moreau_jean, e = 0) ... 1.3e-2 -> 3.3e-3 (spook_contacts,
    e = 1)), and is below 15 h; the slider stays on the loop to O(h^2) and behind the stop
    but for the impact step's motion (h |x'| at most)."""
    diffs = []
    for h in (1e-3, 2.5e-4):
        minimal = _crank(generated, "slider_crank_stop", "moreau_jean", h, e)
        constrained = _crank(generated, "slider_crank_stop_constrained", method, h, e)
        diffs.append(np.abs(minimal.q[:, 0] - constrained.q[:, 0]).max())
        assert constrained.constraint_error.max() <= 20 * h * h
        assert constrained.q[:, 1].max() <= X_STOP + 5 * h * abs(W0) * R
    assert diffs[0] <= 15 * 1e-3 and diffs[1] <= diffs[0] / 2


@pytest.mark.parametrize("method", METHODS)
def test_plastic_stop_holds_the_constrained_slider(generated, method):
    """e = 0: after the impact the slider rests at the stop (x' = 0, the contact active) with
    the torque holding it there, the crank at the angle th_s of the loop closure with
    x = x_stop. The rate there follows from the energy integral
    (J + m x'(th)^2) th'^2 / 2 - tau th = E0. moreau_jean keeps the impact step's overshoot,
    x - x_stop <= h |x'_s| (its rows act on velocities); spook_contacts' stabilized row removes
    it (it rests within O(h^2) of the stop)."""
    h = 1e-3
    traj = _crank(generated, "slider_crank_stop_constrained", method, h, 0.0)
    th_s = math.acos((X_STOP**2 + R**2 - L**2) / (2 * X_STOP * R))
    e0 = (J + M * _slider_rate(TH0_CRANK)**2) * W0**2 / 2 - TAU * TH0_CRANK
    rate_s = math.sqrt(2 * (e0 + TAU * th_s) / (J + M * _slider_rate(th_s)**2))
    overshoot = h * abs(_slider_rate(th_s)) * rate_s
    assert np.abs(traj.v[-100:]).max() <= 1e-6
    past = traj.q[-1, 1] - X_STOP
    if method == "moreau_jean":
        assert 0.0 <= past <= overshoot
    else:        # on the stop within the last step's free motion (measured 7e-7 short of it)
        assert abs(past) <= 10 * h * h
    assert abs(traj.q[-1, 0] - th_s) <= h * rate_s
    assert traj.saved["active_contacts"][-1, 0] == 1 and traj.saved["normal_impulse"][-1, 0] > 0
