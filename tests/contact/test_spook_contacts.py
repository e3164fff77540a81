"""spook_contacts against closed forms: the bouncing ball (impact times, apex heights, rest, the
static stretch of a compliant floor), the block on a ramp (sticking, and sliding with
g (sin a - mu cos a) exactly as the scheme's own closed form), Newton's cradle's simultaneous
impact, the rocking block at rest with a large step and its penetration removed by the
stabilized rows; the energy balance; the refusals and bad settings.

The scheme (methods/spook_contacts.py): v+ from one linear system plus the contact impulses,
q+ = q + h v+. Under gravity alone that is exact in v and gives y_n = y_0 + h sum v_k, so the
position lags the exact parabola by h g t / 2 and E - h m g v / 2 (not E) is kept exactly;
with the impulses' work W = r (u- + u+) / 2 the identity E - h m g v / 2 - W = const holds to
rounding whatever the impulses (v+ = v_free + r / m, y+ = y + h v+). Impacts: Newton's law on
the approaching velocity in the step where the free motion would close the gap, so each impact
time is off by at most about h and each rebound height by about h V0, adding up over the
impacts as for moreau_jean (tests/contact/test_moreau_jean.py). A resting contact with
compliance epsilon settles where the regularized row balances the weight: gap = -epsilon m g.
"""

import math

import numpy as np
import pytest

from lagrange_gen import SimulationError
from lagrange_gen.run.simulate import simulate

G, E, H0 = 9.81, 0.8, 1.0
V0, T1 = math.sqrt(2 * G * H0), math.sqrt(2 * H0 / G)
T_INF = T1 * (1 + E) / (1 - E)


def _ball(generated, h, t_end=5.0, **settings):
    return simulate(generated("bouncing_ball"), method="spook_contacts", q0=[H0], v0=[0.0],
                    t_end=t_end, h=h, params={"g": G, "e": E}, **settings)


def _impact_rows(traj):
    pn = traj.saved["normal_impulse"][:, 0]
    return np.flatnonzero((pn > 0) & (np.concatenate([[0.0], pn[:-1]]) == 0))


def test_bouncing_ball_impact_times_apex_heights_and_rest(generated):
    h = 1e-3
    traj = _ball(generated, h)
    rows = _impact_rows(traj)
    exact = T1 + np.concatenate([[0.0], np.cumsum([2 * E**j * V0 / G for j in range(1, 8)])])
    for k in range(6):
        assert abs(traj.t[rows[k]] - exact[k]) <= 3 * (k + 1) * h, k
    for k in range(1, 6):
        apex = traj.q[rows[k - 1]:rows[k], 0].max()
        assert abs(apex - E**(2 * k) * H0) <= 1.5 * k * h * V0, k
    # rigid floor: the impact step stops at the floor or above it (measured min gap 2.5e-7)
    assert traj.saved["min_gap"].min() >= -h * V0
    # at rest after the accumulation time, on the floor within the last step's free fall
    assert traj.t[np.flatnonzero(np.abs(traj.v[:, 0]) > 1e-12)[-1]] <= T_INF + 60 * h
    assert abs(traj.q[-1, 0]) <= G * h * h and traj.saved["active_contacts"][-1, 0] == 1


def test_apex_heights_converge_at_first_order(generated):
    """The third apex's error against e^6 h0 shrinks at least by half when h does by four."""
    errors = []
    for h in (2e-3, 5e-4):
        traj = _ball(generated, h, t_end=3.0)
        rows = _impact_rows(traj)
        errors.append(abs(traj.q[rows[2]:rows[3], 0].max() - E**6 * H0))
    assert errors[1] <= errors[0] / 2 and errors[0] <= 4.5 * 2e-3 * V0


def test_compliant_floor_holds_the_ball_at_its_static_stretch(generated):
    """With compliance epsilon the resting row reads Sigma p + (4/h) Upsilon g = 0 with
    p = h m g: the gap settles at -epsilon m g (m = 1), the stretch of a spring of stiffness
    1 / epsilon under the weight; the impacts dig in like that spring, by about V0 sqrt(epsilon)."""
    eps = 1e-4
    traj = _ball(generated, 1e-3, compliance=eps)
    assert traj.q[-1, 0] == pytest.approx(-eps * G, rel=1e-9)
    assert abs(traj.v[-1, 0]) <= 1e-9
    assert -1.2 * V0 * math.sqrt(eps) <= traj.saved["min_gap"].min() <= -0.5 * V0 * math.sqrt(eps)


def test_energy_balance_closes_with_the_schemes_modified_energy(generated):
    h = 1e-3
    traj = _ball(generated, h)
    work = traj.saved["contact_work"][:, 0]
    modified = traj.energy - h * G * traj.v[:, 0] / 2
    assert np.abs(modified - modified[0] - work).max() <= 1e-11 * G * H0
    # E itself: off by that O(h) term only, no drift
    assert np.abs(traj.energy - traj.energy[0] - work).max() <= h * G * V0 / 2 * 1.01
    assert work[-1] == pytest.approx(-traj.energy[0] + traj.energy[-1], abs=h * G * V0)


def _ramp(generated, mu, h, a=0.5, t_end=1.0):
    traj = simulate(generated("block_on_ramp"), method="spook_contacts", q0=[0.0, 0.0],
                    t_end=t_end, h=h, params={"g": G, "a": a, "mu": mu})
    X, Y = traj.q[:, 0], traj.q[:, 1]
    return traj, X * math.cos(a) - Y * math.sin(a), X * math.sin(a) + Y * math.cos(a)


def test_block_on_ramp_slides_with_the_coulomb_acceleration_at_first_order(generated):
    """tan a > mu: v = g (sin a - mu cos a) t exactly, s = acc t^2 / 2 + acc h t / 2 (the
    scheme's lag, to rounding), the gap stays 0; the error against acc t^2 / 2 has order 1."""
    a, mu = 0.5, 0.3
    acc = G * (math.sin(a) - mu * math.cos(a))
    errors = []
    for h in (1e-2, 5e-3, 2.5e-3):
        traj, s, gap = _ramp(generated, mu, h)
        np.testing.assert_allclose(s, acc * traj.t**2 / 2 + acc * h * traj.t / 2, rtol=0,
                                   atol=1e-13)
        assert np.abs(gap).max() <= 1e-14
        speed = traj.v[:, 0] * math.cos(a) - traj.v[:, 1] * math.sin(a)
        np.testing.assert_allclose(speed, acc * traj.t, rtol=0, atol=1e-13)
        friction = traj.saved["tangent_impulse"][1:, 0]
        np.testing.assert_allclose(friction, -mu * traj.saved["normal_impulse"][1:, 0],
                                   rtol=1e-12)
        errors.append(np.abs(s - acc * traj.t**2 / 2).max())
    order = np.polyfit(np.log([1e-2, 5e-3, 2.5e-3]), np.log(errors), 1)[0]
    assert order == pytest.approx(1.0, abs=0.02)


def test_block_on_ramp_sticks_below_the_friction_angle(generated):
    traj, s, gap = _ramp(generated, 0.7, 1e-2)          # tan 0.5 = 0.546 < 0.7
    assert np.abs(s).max() <= 1e-15 and np.abs(gap).max() <= 1e-15
    # the friction impulse holds the weight's component along the plane, inside the bound
    pt, pn = traj.saved["tangent_impulse"][1:, 0], traj.saved["normal_impulse"][1:, 0]
    np.testing.assert_allclose(np.abs(pt), 1e-2 * G * math.sin(0.5), rtol=1e-12)
    assert (np.abs(pt) < 0.7 * pn).all()


@pytest.mark.parametrize("e", [1.0, 0.0])
def test_newtons_cradle_simultaneous_impact(generated, e):
    """Ball 1 at V on balls 2 and 3 at rest, touching: both contacts in one step, Newton's law
    on both (tests/contact/test_newtons_cradle.py derives the outcome):
    v+ = ((1 - 2e) V / 3, (1 + e) V / 3, (1 + e) V / 3); momentum exact."""
    r, v, gap = 0.1, 1.0, 0.0537
    q0 = np.array([0.0, 2 * r + gap, 4 * r + gap])
    traj = simulate(generated("newtons_cradle"), method="spook_contacts", q0=q0,
                    v0=[v, 0.0, 0.0], t_end=0.5, h=1e-3, params={"r": r, "e": e})
    after = np.array([(1 - 2 * e) * v / 3, (1 + e) * v / 3, (1 + e) * v / 3])
    np.testing.assert_allclose(traj.v[-1], after, rtol=0, atol=1e-9 * v)
    # one impact, two contacts (balls 2 and 3 touch at a gap of -6e-17 after rounding, which the
    # stabilized row opens with impulses of that size)
    rows = np.flatnonzero(traj.saved["normal_impulse"].max(axis=1) > 1e-12 * v)
    assert len(rows) == 1 and traj.saved["active_contacts"][rows[0], 0] == 2
    np.testing.assert_allclose(traj.v.sum(axis=1), v, rtol=0, atol=1e-14)
    assert abs(traj.t[rows[0]] - gap / v) <= 1e-3
    assert traj.saved["min_gap"].min() >= -1e-15


def _block(generated, y0, h, method="spook_contacts", t_end=2.0, **options):
    return simulate(generated("rocking_block"), method=method, q0=[0.0, y0, 0.0], t_end=t_end,
                    h=h, **options)


def test_block_rests_on_the_floor_with_a_large_step(generated):
    """The rocking block (half-height 0.6, both corners on the floor) at h = 0.05: the rows
    hold it exactly (rounding and the Gauss-Seidel tolerance: measured 1.1e-10)."""
    traj = _block(generated, 0.6, 0.05)
    assert np.abs(traj.q - [0.0, 0.6, 0.0]).max() <= 1e-9
    assert np.abs(traj.v).max() <= 1e-9
    assert traj.saved["min_gap"].min() >= -1e-9
    assert (traj.saved["active_contacts"][1:, 0] == 2).all()


def test_stabilized_rows_remove_a_penetration(generated):
    """Started 0.01 into the floor at rest: the first step moves the gap to g (1 - 4 Upsilon)
    (spook's row with u- = 0, Upsilon = 1/9 at d = 2), and the gap goes to 0 (the row's step
    matrix has spectral radius below 1); moreau_jean keeps the penetration (its rows act on
    velocities only). penetration="keep" starts them there (the default projects q0 out)."""
    h, g0 = 0.05, -0.01
    with pytest.warns(UserWarning, match="inside contact"):
        traj = _block(generated, 0.6 + g0, h, penetration="keep")
    gaps = traj.saved["min_gap"][:, 0]
    assert gaps[1] == pytest.approx(g0 * (1 - 4 / 9), rel=1e-9)
    assert abs(gaps[-1]) <= 1e-9 and np.abs(traj.v[-1]).max() <= 1e-9
    with pytest.warns(UserWarning, match="inside contact"):
        kept = _block(generated, 0.6 + g0, h, method="moreau_jean", t_end=0.5,
                      penetration="keep")
    assert kept.saved["min_gap"][-1, 0] == pytest.approx(g0, rel=1e-9)


@pytest.mark.parametrize("setting, value, message", [
    ("compliance", -1.0, r"compliance must be a finite number >= 0, got -1.0"),
    ("relaxation", 0.0, r"relaxation must be a finite number > 0, got 0.0"),
    ("contact_tol", 0.0, r"contact_tol must be a finite number > 0, got 0.0"),
    ("max_sweeps", 0, r"max_sweeps must be a positive integer, got 0"),
    ("theta", 0.5, r"method 'spook_contacts' has no setting 'theta'"),
])
def test_bad_settings_are_refused_in_one_line(generated, setting, value, message):
    with pytest.raises(SimulationError, match=message) as info:
        _ball(generated, 1e-3, t_end=0.01, **{setting: value})
    assert "\n" not in str(info.value)


def test_contact_problem_gauss_seidel_leaves_is_answered_by_lemke(generated):
    """One Gauss-Seidel sweep is too few for a sliding block (the normal and the tangential
    impulse need a second sweep to be seen unchanged); Lemke's method (core/contact_lcp.py)
    then answers, with the impulses of the converged sweeps (2D friction: the LCP is exact)."""
    runs = [simulate(generated("block_on_ramp"), method="spook_contacts", q0=[0.0, 0.0], t_end=0.01,
                     h=1e-3, **options) for options in ({}, {"max_sweeps": 1})]
    for field in ("normal_impulse", "tangent_impulse"):
        np.testing.assert_allclose(runs[1].saved[field], runs[0].saved[field], rtol=1e-9,
                                   atol=1e-15)
    np.testing.assert_allclose(runs[1].q, runs[0].q, rtol=1e-9, atol=1e-15)


def test_spook_refuses_contacts_and_spook_contacts_a_model_without(generated):
    with pytest.raises(SimulationError, match=r"spook.*ignores the model's unilateral contacts "
                                              r"\(use moreau_jean, spook_contacts"):
        simulate(generated("pendulum_wall_cartesian"), method="spook", q0=[0.0, -1.0],
                 t_end=0.01, h=1e-3)
    with pytest.raises(SimulationError, match=r"spook_contacts.*unilateral contacts and this "
                                              r"model has none"):
        simulate(generated("cartesian_pendulum"), method="spook_contacts", q0=[0.0, -1.0],
                 t_end=0.01, h=1e-3)
