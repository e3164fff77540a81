"""The 3D friction cone (Coulomb's disk |(p_T1, p_T2)| <= mu p_N) against closed forms.

A puck on a horizontal table (models/puck_on_table.py) launched at speed V0 along a direction
PHI that is not a tangent axis slides in a straight line along it, decelerating at mu g, and
stops at the time V0 / (mu g) after V0^2 / (2 mu g). A box-shaped law (|p_x|, |p_y| <= mu p_N
each: the "pyramid") would decelerate both components at mu g, stop the smaller one first and
bend the path: the straight-line checks catch it. dop853_impacts integrates the parabola
exactly and locates the stop (the slip's zero) on its dense output; moreau_jean's sliding steps
are exact under constant forces and its error is the stop step's, a closed form in h.

A puck launched sideways on an incline with tan(a) < mu (models/puck_on_incline.py) slides on a
curving path (friction along the turning slip direction, gravity downhill) and comes to rest.
The reference is an independent integration of the same law written directly in the plane's
coordinates (scipy's DOP853, stopped where the speed falls to 1e-10): the rest point and time;
and the energy balance E - E0 - W (W the friction's work) closes.
"""

import math
import re

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from lagrange_gen.cli.main import main
from lagrange_gen.run.simulate import simulate

G, MU, V0, PHI = 9.81, 0.3, 2.0, 0.6
T_STOP, D_STOP = V0 / (MU * G), V0**2 / (2 * MU * G)
DIRECTION = np.array([math.cos(PHI), math.sin(PHI)])
SLIDE, STICK = 4, 1


def _puck(module, method, **settings):
    return simulate(module, method=method, q0=[0.0, 0.0, 0.0],
                    v0=[V0 * DIRECTION[0], V0 * DIRECTION[1], 0.0], t_end=1.0,
                    params={"g": G, "mu": MU}, **settings)


@pytest.fixture(scope="module")
def puck(generated):
    return generated("puck_on_table")


def test_puck_slides_straight_and_stops_where_the_disk_says(puck):
    traj = _puck(puck, "dop853_impacts")
    xy = traj.q[:, :2]
    lateral = xy[:, 0] * DIRECTION[1] - xy[:, 1] * DIRECTION[0]
    assert np.abs(lateral).max() <= 1e-13                 # a straight line along v0
    along = xy @ DIRECTION
    sliding = traj.t <= T_STOP
    exact = V0 * traj.t - MU * G * traj.t**2 / 2
    assert np.abs(along[sliding] - exact[sliding]).max() <= 1e-12
    assert np.abs(xy[-1] - D_STOP * DIRECTION).max() <= 1e-12
    switch = np.flatnonzero(np.diff(traj.saved["contact_mode"][:, 0]))
    assert len(switch) == 1 and traj.t[switch[0]] == pytest.approx(T_STOP, abs=1e-12)
    assert traj.saved["contact_mode"][0, 0] == SLIDE and traj.saved["contact_mode"][-1, 0] == STICK
    assert np.abs(traj.v[-1]).max() <= 1e-12 and np.abs(traj.q[:, 2]).max() <= 1e-14
    residual = traj.energy - traj.energy[0] - traj.saved["contact_work"][:, 0]
    assert np.abs(residual).max() <= 1e-13 * V0**2
    assert traj.saved["contact_work"][-1, 0] == pytest.approx(-V0**2 / 2, abs=1e-12)


def test_moreau_jean_stop_step_error_and_the_line(puck):
    """Under constant forces the sliding steps are exact (each friction impulse is mu m g h
    against the slip, theta = 1/2); the error is the stop step's: it starts at t_k = k h with
    v_k = V0 - mu g t_k <= mu g h, the sticking impulse zeroes v, and the puck moves
    h v_k / 2 instead of v_k^2 / (2 mu g): past the stop point by mu g tau (h - tau) / 2 with
    tau = v_k / (mu g) <= h
    (at most mu g h^2 / 8: second order here, with a constant that depends on where the stop
    falls in its step, so it is checked per h rather than by a fitted order). The impulse pair
    opposes the slip exactly, so the path stays on the line to rounding."""
    for h in (1e-2, 7e-3, 2.5e-3):
        traj = _puck(puck, "moreau_jean", h=h)
        xy = traj.q[:, :2]
        assert np.abs(xy[:, 0] * DIRECTION[1] - xy[:, 1] * DIRECTION[0]).max() <= 1e-14
        assert np.abs(traj.v[-1]).max() <= 1e-14          # at rest: the sticking impulse
        k = math.floor(T_STOP / h)
        v_k = V0 - MU * G * k * h
        if v_k > MU * G * h:            # T_STOP within rounding of a step's end
            k, v_k = k + 1, v_k - MU * G * h
        tau = v_k / (MU * G)
        past = MU * G * tau * (h - tau) / 2
        assert xy[-1] @ DIRECTION - D_STOP == pytest.approx(past, abs=1e-13)
        assert 0.0 <= past <= MU * G * h * h / 8


def test_the_cli_reports_the_puck(puck, capsys):
    assert main(["simulate", puck.__file__, "--method", "dop853_impacts", "--t-end", "1",
                 "--q0", "0", "0", "0", "--v0", str(V0 * DIRECTION[0]), str(V0 * DIRECTION[1]),
                 "0", "--param", f"g={G},mu={MU}"]) == 0
    out = capsys.readouterr().out
    final = re.search(r"final q = \[(\S+), (\S+), (\S+)\]", out)
    assert final, out
    assert [float(final.group(1)), float(final.group(2))] == \
        pytest.approx(list(D_STOP * DIRECTION), abs=1e-8)         # 9 digits printed
    assert re.search(r"W the work of the contact impulses and of the persistent contacts' "
                     r"forces, final W = -2\)", out), out        # -m V0^2 / 2


A, MU_INCLINE, V_SIDE = 0.3, 0.5, 1.5


def _incline_reference():
    """The sliding law in the plane's coordinates (s1 across, s2 up the slope), integrated
    directly: s'' = (0, -g sin a) - mu g cos a u / |u|, stopped at |u| = 1e-10. Returns (time,
    position) of the rest."""
    def rhs(t, y):
        u = y[2:]
        speed = math.hypot(*u)
        friction = -MU_INCLINE * G * math.cos(A) * u / speed
        return [u[0], u[1], friction[0], -G * math.sin(A) + friction[1]]

    def stops(t, y):
        return math.hypot(y[2], y[3]) - 1e-10
    stops.terminal = True
    sol = solve_ivp(rhs, (0.0, 10.0), [0.0, 0.0, V_SIDE, 0.0], method="DOP853", rtol=1e-13,
                    atol=1e-14, events=stops)
    return sol.t_events[0][0], sol.y_events[0][0][:2]


@pytest.fixture(scope="module")
def incline(generated):
    return simulate(generated("puck_on_incline"), method="dop853_impacts", q0=[0.0, 0.0, 0.0],
                    v0=[0.0, V_SIDE, 0.0], t_end=1.0,
                    params={"g": G, "a": A, "mu": MU_INCLINE})


def test_puck_on_incline_curves_and_comes_to_rest(incline):
    traj = incline
    t_rest, rest = _incline_reference()
    up = np.array([-math.cos(A), 0.0, math.sin(A)])     # t2 = n x N.y
    s1, s2 = traj.q[:, 1], traj.q @ up
    assert s2[-1] < -0.01                        # it curved downhill from a sideways launch
    assert abs(s1[-1] - rest[0]) <= 1e-8 and abs(s2[-1] - rest[1]) <= 1e-8
    switch = np.flatnonzero(np.diff(traj.saved["contact_mode"][:, 0]))
    assert len(switch) == 1 and traj.t[switch[0]] == pytest.approx(t_rest, abs=1e-8)
    assert traj.saved["contact_mode"][-1, 0] == STICK and np.abs(traj.v[-1]).max() <= 1e-12
    normal = np.array([math.sin(A), 0.0, math.cos(A)])
    assert np.abs(traj.q @ normal).max() <= 1e-12         # on the plane
    # the friction's power along the curving path, integrated with the state at the stages of
    # steps taken to rtol = 1e-9
    residual = traj.energy - traj.energy[0] - traj.saved["contact_work"][:, 0]
    assert np.abs(residual).max() <= 1e-10 * V_SIDE**2


def test_puck_on_incline_moreau_jean_balance_and_rest(generated):
    """theta = 1/2 under gravity alone: E - E0 - W closes to rounding; the rest point within
    O(h) of the reference."""
    traj = simulate(generated("puck_on_incline"), method="moreau_jean", q0=[0.0, 0.0, 0.0],
                    v0=[0.0, V_SIDE, 0.0], t_end=1.0, h=1e-3,
                    params={"g": G, "a": A, "mu": MU_INCLINE})
    residual = traj.energy - traj.energy[0] - traj.saved["contact_work"][:, 0]
    assert np.abs(residual).max() <= 1e-12 * V_SIDE**2
    _, rest = _incline_reference()
    up = np.array([-math.cos(A), 0.0, math.sin(A)])
    assert np.hypot(traj.q[-1, 1] - rest[0], traj.q[-1] @ up - rest[1]) <= 2e-3 * V_SIDE
    assert np.abs(traj.v[-1]).max() <= 1e-12
