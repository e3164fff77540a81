"""dop853_impacts (event-driven contacts) against closed forms: the bouncing ball (impact times,
rebound speeds and apex heights, impulses, the Zeno accumulation time and the rest after it),
the block on a ramp (sticking, sliding, launched uphill: stopping time and distance, then
sticking or sliding back), Newton's cradle's simultaneous impact at t0; the energy balance
E - E0 - W_contact.

Why the tolerances: between switches the motion is a polynomial of degree 2 in t (constant
forces), which dop853 integrates exactly; the switch times are roots of its dense output,
refined to events.ROOT_RTOL (1e-12) of the step, and the impulses come from the contact problem
solved to contact_tol = 1e-12. So the impact times and velocities are exact to about 1e-11 after
tens of impacts (rounding accumulated), and the energy balance closes to rounding.

The Zeno guard (zeno_interval = delta): the impact intervals of the ball are
Delta_k = 2 e^k V0 / g, decreasing by e; the guard makes plastic the first impact k whose
interval Delta_k < delta, so Delta_k >= e delta, and the ball rests from
t_k = t_inf - Delta_k e / (1 - e), in [t_inf - delta e / (1 - e), t_inf - delta e^2 / (1 - e)].
"""

import math

import numpy as np
import pytest

from lagrange_gen import SimulationError
from lagrange_gen.run.simulate import simulate

G, E, H0 = 9.81, 0.8, 1.0
V0, T1 = math.sqrt(2 * G * H0), math.sqrt(2 * H0 / G)
T_INF = T1 * (1 + E) / (1 - E)
DELTA = 1e-3


@pytest.fixture(scope="module")
def ball(generated):
    return simulate(generated("bouncing_ball"), method="dop853_impacts", q0=[H0], v0=[0.0],
                    t_end=T_INF + 1.0, params={"g": G, "e": E}, zeno_interval=DELTA)


def _impact_rows(traj):
    """Rows after each impact (every-step mode writes the state before and after it)."""
    return np.flatnonzero(np.diff(traj.saved["impacts"][:, 0]) > 0) + 1


def test_ball_impact_times_speeds_and_impulses(ball):
    rows = _impact_rows(ball)
    k = np.arange(1, 21)
    exact_t = T1 + np.concatenate([[0.0], np.cumsum(2 * E**k[:-1] * V0 / G)])
    assert np.abs(ball.t[rows[:20]] - exact_t).max() <= 1e-10
    assert np.abs(ball.v[rows[:20], 0] - E**k * V0).max() <= 1e-10
    # the row before each impact: the ball on the floor, arriving at e^(k-1) V0
    assert np.abs(ball.q[rows[:20] - 1, 0]).max() <= 1e-10
    assert np.abs(ball.v[rows[:20] - 1, 0] + E**(k - 1) * V0).max() <= 1e-10
    impulse = np.diff(ball.saved["normal_impulse_sum"][:, 0])[rows[:20] - 1]
    assert np.abs(impulse - (1 + E) * E**(k - 1) * V0).max() <= 1e-10      # m = 1
    table = ball.impacts                  # the same, as Trajectory.impacts gives them
    assert len(table) == int(ball.saved["impacts"][-1, 0])
    assert np.array_equal(table["t"][:20], ball.t[rows[:20]])
    assert np.array_equal(table["normal"][:20], impulse) and (table["contact"] == 0).all()


def test_ball_apex_heights(generated):
    """y at the closed-form apex times t_k + e^k V0 / g is e^(2k) h0 (t_eval: dense output)."""
    k = np.arange(1, 8)
    impacts = T1 + np.concatenate([[0.0], np.cumsum(2 * E**k[:-1] * V0 / G)])
    apex_t = impacts + E**k * V0 / G
    traj = simulate(generated("bouncing_ball"), method="dop853_impacts", q0=[H0], v0=[0.0],
                    t_end=apex_t[-1] + 0.01, t_eval=apex_t, params={"g": G, "e": E})
    assert np.array_equal(traj.t, apex_t)
    assert np.abs(traj.q[:, 0] - E**(2 * k) * H0).max() <= 1e-10
    assert np.abs(traj.v[:, 0]).max() <= 1e-9


def test_ball_comes_to_rest_at_the_accumulation_time(ball):
    rows = _impact_rows(ball)
    t_rest = ball.t[rows[-1]]
    assert T_INF - DELTA * E / (1 - E) <= t_rest <= T_INF - DELTA * E**2 / (1 - E)
    assert np.abs(ball.v[rows[-1]:, 0]).max() == 0.0
    assert np.abs(ball.q[rows[-1]:, 0]).max() <= 1e-10
    assert (ball.saved["contact_mode"][rows[-1]:, 0] == 1).all()
    assert (ball.saved["contact_mode"][:rows[-1], 0] == 0).all()
    assert ball.t[-1] == T_INF + 1.0


def test_ball_energy_balance_closes(ball):
    """E - E0 - W_contact = 0: the impulses' work r (u- + u+) / 2 is the kinetic energy change."""
    residual = ball.energy - ball.energy[0] - ball.saved["contact_work"][:, 0]
    assert np.abs(residual).max() <= 1e-12 * G * H0
    assert ball.energy[-1] == pytest.approx(0.0, abs=1e-12)


A = 0.5         # ramp angle: tan a = 0.546


@pytest.mark.parametrize("mu, u0", [(0.3, 0.0), (0.6, 0.0), (0.6, -2.0), (0.3, -2.0)])
def test_block_on_ramp(generated, mu, u0):
    """Released at rest: slides with g (sin a - mu cos a) for tan a > mu, sticks otherwise.
    Launched uphill at speed |u0|: decelerates at g (sin a + mu cos a) until it stops at
    t_s = |u0| / (g (sin a + mu cos a)), |u0| t_s / 2 up the ramp; then it sticks (tan a < mu)
    or slides back down with g (sin a - mu cos a)."""
    c, s = math.cos(A), math.sin(A)
    traj = simulate(generated("block_on_ramp"), method="dop853_impacts", q0=[0.0, 0.0],
                    v0=[u0 * c, -u0 * s], t_end=1.0, params={"g": G, "a": A, "mu": mu})
    along = traj.q[:, 0] * c - traj.q[:, 1] * s          # downhill distance
    down = G * (s - mu * c)
    if u0 == 0.0:
        t_stop, s_stop = 0.0, 0.0
    else:
        t_stop = -u0 / (G * (s + mu * c))
        s_stop = u0 * t_stop / 2
        switch = np.flatnonzero(np.diff(traj.saved["contact_mode"][:, 0]))
        assert len(switch) == 1 and traj.t[switch[0]] == pytest.approx(t_stop, abs=1e-12)
    exact = s_stop + (0.5 * down * (1.0 - t_stop)**2 if down > 0 else 0.0)
    assert along[-1] == pytest.approx(exact, abs=1e-12)
    assert np.abs(traj.q[:, 0] * s + traj.q[:, 1] * c).max() <= 1e-14     # on the ramp
    final_mode = 2 if down > 0 else 1                    # sliding downhill / sticking
    assert traj.saved["contact_mode"][-1, 0] == final_mode
    residual = traj.energy - traj.energy[0] - traj.saved["contact_work"][:, 0]
    assert np.abs(residual).max() <= 1e-13 * G
    # friction's work: -mu m g cos a times the path slid (up to the stop, then down)
    path = abs(s_stop) + abs(exact - s_stop)
    assert traj.saved["contact_work"][-1, 0] == pytest.approx(-mu * G * c * path, abs=1e-12)


def test_rocking_block_keeps_housners_energy_fraction_per_impact(generated):
    """Housner's rocking block (tests/contact/test_rocking_block.py) released tilted by 0.15 on
    its left corner, e = 0, mu = 1: it pivots on the sticking corner (persistent, its gap held
    at the acceleration level with the contact_rates term), and each impact on the other corner
    keeps (E - m g c) / (E0 - m g c) = r^k, r = (1 - 3/2 sin^2 alpha)^2, the corner hit taking
    over as the pivot while the other lifts (modes (1, 0) and (0, 1) alternate). Between
    impacts E is conserved to the tolerance (rtol = 1e-10: 1e-8 of the ratio after 6)."""
    b, c, phi0 = 0.2, 0.6, 0.15
    r = (1 - 1.5 * math.sin(math.atan2(b, c))**2) ** 2
    q0 = [-b + b * math.cos(phi0) - c * math.sin(phi0), b * math.sin(phi0) + c * math.cos(phi0),
          phi0]
    traj = simulate(generated("rocking_block"), method="dop853_impacts", q0=q0, t_end=2.1,
                    rtol=1e-10, atol=1e-12,
                    params={"g": G, "b": b, "c": c, "e": 0.0, "mu": 1.0, "a_ground": 0.0})
    rows = _impact_rows(traj)
    assert len(rows) == 5
    ratio = (traj.energy - G * c) / (traj.energy[0] - G * c)
    assert np.abs(ratio[rows] - r ** np.arange(1, 6)).max() <= 1e-8
    modes = traj.saved["contact_mode"][rows]
    assert (modes == [[0, 1], [1, 0], [0, 1], [1, 0], [0, 1]]).all()
    left_lifts = np.diff(traj.saved["normal_impulse_sum"][:, 0])[rows[0] - 1]
    assert left_lifts == 0.0                 # the pivot takes no impulse: Housner's assumption
    residual = traj.energy - traj.energy[0] - traj.saved["contact_work"][:, 0]
    assert np.abs(residual).max() <= 1e-8 * G * c


def test_newtons_cradle_simultaneous_impact_at_t0(generated):
    """Ball 1 at V touching balls 2 and 3 at rest: one impact problem on both contacts gives
    ((1 - 2e) V / 3, (1 + e) V / 3, (1 + e) V / 3) (tests/contact/test_newtons_cradle.py).
    Row 0 is the state after the start's impact, its impulses in the sums; the contact work
    counts from row 0."""
    r, v, e = 0.1, 1.0, 0.5
    traj = simulate(generated("newtons_cradle"), method="dop853_impacts",
                    q0=[0.0, 2 * r, 4 * r], v0=[v, 0.0, 0.0], t_end=0.5,
                    params={"r": r, "e": e})
    expected = np.array([(1 - 2 * e) * v / 3, (1 + e) * v / 3, (1 + e) * v / 3])
    assert np.abs(traj.v[0] - expected).max() <= 1e-11
    assert np.abs(traj.v[-1] - expected).max() <= 1e-11
    assert traj.saved["impacts"][-1, 0] == 1.0
    p2 = (1 + e) * v / 3                                  # m = 1
    assert np.abs(traj.saved["normal_impulse_sum"][0] - [2 * p2, p2]).max() <= 1e-11
    residual = traj.energy - traj.energy[0] - traj.saved["contact_work"][:, 0]
    assert np.abs(residual).max() <= 1e-14


def test_settings_are_checked(generated):
    with pytest.raises(SimulationError, match="zeno_interval"):
        simulate(generated("bouncing_ball"), method="dop853_impacts", q0=[H0], v0=[0.0],
                 t_end=1.0, zeno_interval=-1.0)


def test_zeno_guard_survives_the_drivers_chunks(generated, monkeypatch):
    """The driver calls the glue again when its row buffers fill (run/adaptive_driver.py): with
    buffers of 4 rows the impacts near the accumulation time fall in different calls. The
    guard's memory (the saved last_impact) crosses them: the ball still comes to rest within
    the bracket of test_ball_comes_to_rest_at_the_accumulation_time, after the same impacts
    as in one call. Without it each call would forget the last impact and the ball would
    bounce on until rest_velocity stopped it, far more impacts later."""
    from lagrange_gen.run import adaptive_driver
    module = generated("bouncing_ball")
    whole = simulate(module, method="dop853_impacts", q0=[H0], v0=[0.0], t_end=T_INF + 0.1,
                     params={"g": G, "e": E}, zeno_interval=DELTA)
    monkeypatch.setattr(adaptive_driver, "FIRST_ROWS", 4)
    monkeypatch.setattr(adaptive_driver, "CHUNK_ROWS", 4)
    chunked = simulate(module, method="dop853_impacts", q0=[H0], v0=[0.0], t_end=T_INF + 0.1,
                       params={"g": G, "e": E}, zeno_interval=DELTA)
    rows = _impact_rows(chunked)
    assert chunked.saved["impacts"][-1, 0] == whole.saved["impacts"][-1, 0]
    t_rest = chunked.t[rows[-1]]
    assert T_INF - DELTA * E / (1 - E) <= t_rest <= T_INF - DELTA * E**2 / (1 - E)
    assert t_rest == pytest.approx(whole.t[_impact_rows(whole)[-1]], abs=1e-12)
    last = chunked.saved["last_impact"][-1, 0]
    assert last == t_rest and whole.saved["last_impact"][0, 0] == -np.inf
