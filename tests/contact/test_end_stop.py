"""A slider-crank hitting its end stop (models/slider_crank_stop.py) under dop853_impacts,
against closed forms and conservation identities.

Crank (inertia J) at th0 = pi/2 turning back at rate w0 towards the stop, a torque tau pushing
it on. Closed forms: the stop is reached at cos th_s = (x_stop^2 + r^2 - L^2) / (2 x_stop r)
(the loop closure solved for the crank angle); the energy E = (J + m x'(th)^2) th'^2 / 2 - tau th
is conserved in flight, which gives the rate there, th'_s^2 = 2 (E0 + tau th_s) / (J + m x'_s^2),
and the time to get there, t_s = integral from th_s to th0 of dth / |th'(th)| (quadrature of the
energy integral, written here directly, not through derive/). Newton's law with one coordinate:
th'+ = -e th'-. e = 1: the energy is the same after the impact (the impulse does no work);
e = 0: the slider stops at the stop and stays there (tau pushes it on), the impact having taken
all the kinetic energy.

Tolerances: rtol = 1e-10 between impacts (energy to ~1e-9 relative over the run), the impact
time to the root finder's 1e-12 of a step plus the integration error.
"""

import math

import numpy as np
import pytest
from scipy.integrate import quad

from lagrange_gen.run.simulate import simulate

R, L, J, M, TAU, X_STOP = 0.3, 1.0, 0.05, 1.0, -1.0, 1.25
TH0, W0 = math.pi / 2, -1.0


def _slider_rate(th):
    """dx/dth of x(th) = r cos th + sqrt(L^2 - r^2 sin^2 th)."""
    return -R * math.sin(th) - R**2 * math.sin(th) * math.cos(th) / math.sqrt(
        L**2 - R**2 * math.sin(th)**2)


def _inertia(th):
    return J + M * _slider_rate(th)**2


E0 = _inertia(TH0) * W0**2 / 2 - TAU * TH0
TH_STOP = math.acos((X_STOP**2 + R**2 - L**2) / (2 * X_STOP * R))
RATE_STOP = -math.sqrt(2 * (E0 + TAU * TH_STOP) / _inertia(TH_STOP))
T_STOP = quad(lambda th: 1.0 / math.sqrt(2 * (E0 + TAU * th) / _inertia(th)), TH_STOP, TH0,
              epsabs=1e-14, epsrel=1e-13)[0]


def _run(generated, e, t_end=2.5):
    return simulate(generated("slider_crank_stop"), method="dop853_impacts", q0=[TH0],
                    v0=[W0], t_end=t_end, rtol=1e-10, atol=1e-12,
                    params={"r": R, "L": L, "J": J, "m": M, "tau": TAU, "x_stop": X_STOP,
                            "e": e})


def _impact_rows(traj):
    return np.flatnonzero(np.diff(traj.saved["impacts"][:, 0]) > 0) + 1


def test_elastic_end_stop_reverses_the_rate_and_keeps_the_energy(generated):
    traj = _run(generated, 1.0)
    rows = _impact_rows(traj)
    assert len(rows) >= 2
    assert traj.t[rows[0]] == pytest.approx(T_STOP, abs=1e-9)
    assert traj.q[rows[0], 0] == pytest.approx(TH_STOP, abs=1e-10)
    assert traj.v[rows[0] - 1, 0] == pytest.approx(RATE_STOP, abs=1e-8)
    assert traj.v[rows[0], 0] == pytest.approx(-RATE_STOP, abs=1e-8)
    assert np.abs(traj.energy - E0).max() <= 1e-8 * abs(E0)
    assert abs(traj.saved["contact_work"][-1, 0]) <= 1e-12
    x = R * np.cos(traj.q[:, 0]) + np.sqrt(L**2 - R**2 * np.sin(traj.q[:, 0])**2)
    assert x.max() <= X_STOP + 1e-10


def test_plastic_end_stop_stops_the_slider_and_holds_it(generated):
    traj = _run(generated, 0.0)
    rows = _impact_rows(traj)
    assert len(rows) == 1
    k = rows[0]
    assert traj.t[k] == pytest.approx(T_STOP, abs=1e-9)
    assert traj.v[k - 1, 0] == pytest.approx(RATE_STOP, abs=1e-8)
    assert np.abs(traj.v[k:, 0]).max() <= 1e-12                   # the stop's velocity zeroes
    assert np.abs(traj.q[k:, 0] - TH_STOP).max() <= 1e-10         # and stays there
    assert (traj.saved["contact_mode"][k:, 0] == 1).all()
    kinetic = _inertia(TH_STOP) * RATE_STOP**2 / 2
    assert traj.saved["contact_work"][-1, 0] == pytest.approx(-kinetic, rel=1e-8)
    residual = traj.energy - traj.energy[0] - traj.saved["contact_work"][:, 0]
    assert np.abs(residual).max() <= 1e-8 * abs(E0)


def test_moreau_jean_stops_the_slider_at_a_plastic_end_stop(generated):
    """moreau_jean, e = 0: the impulse of the step where the free motion would cross the stop
    zeroes the stop's velocity (Newton's law at the velocity level, exact), and the impulses of
    the following steps hold the slider there; the impact lands within a step of T_STOP and
    the crank within h |th'_s| of TH_STOP (positions move with (v + v+) / 2 in the impact
    step)."""
    h = 1e-3
    traj = simulate(generated("slider_crank_stop"), method="moreau_jean", q0=[TH0], v0=[W0],
                    t_end=1.0, h=h, params={"r": R, "L": L, "J": J, "m": M, "tau": TAU,
                                            "x_stop": X_STOP, "e": 0.0})
    first = np.flatnonzero(traj.saved["normal_impulse"][:, 0] > 0)[0]
    assert abs(traj.t[first] - T_STOP) <= h
    assert np.abs(traj.v[first:, 0]).max() <= 1e-9 * abs(RATE_STOP)
    assert np.abs(traj.q[first:, 0] - TH_STOP).max() <= h * abs(RATE_STOP)
