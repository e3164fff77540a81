"""moreau_jean against closed forms: the bouncing ball (impact times, apex heights, the Zeno
accumulation time) and the block on a ramp (sticking for tan a < mu, sliding with
g (sin a - mu cos a) otherwise); the energy balance E - E0 - W_contact; the refusals.

Why the tolerances: at theta = 1/2 the free flight under constant gravity is exact (v+ = v - g h,
y+ = y + h v - g h^2 / 2), so every error comes from the impact steps. An impact is applied in
the step where the free step would cross the floor, with the velocity u- at the step's start:
its time is off by at most about h, the speed by at most g h, so the next flight time by about
2 e h, and the rebound height by about h V0 (the position moves by h (u- + u+) / 2 in that step).
Those add up over k impacts: |t_k - t_k exact| <= 3 k h and |apex_k - e^(2k) h0| <= 1.5 k h V0.
The block's motion has constant accelerations, which theta = 1/2 integrates exactly: rounding
only.
"""

import math

import numpy as np
import pytest

from lagrange_gen import SimulationError
from lagrange_gen.run.simulate import simulate

G, E, H0 = 9.81, 0.8, 1.0
V0, T1 = math.sqrt(2 * G * H0), math.sqrt(2 * H0 / G)
#: The Zeno accumulation time: t_1 + sum_{k >= 1} 2 e^k V0 / g = sqrt(2 h0 / g) (1 + e) / (1 - e).
T_INF = T1 * (1 + E) / (1 - E)


def _ball(generated, h, t_end=5.0):
    return simulate(generated("bouncing_ball"), method="moreau_jean", q0=[H0], v0=[0.0],
                    t_end=t_end, h=h, params={"g": G, "e": E})


def _impact_rows(traj):
    """Rows whose step began an impact (a normal impulse after a step without one)."""
    pn = traj.saved["normal_impulse"][:, 0]
    return np.flatnonzero((pn > 0) & (np.concatenate([[0.0], pn[:-1]]) == 0))


def test_bouncing_ball_impact_times_and_apex_heights(generated):
    h = 1e-3
    traj = _ball(generated, h)
    rows = _impact_rows(traj)
    exact = T1 + np.concatenate([[0.0], np.cumsum([2 * E**j * V0 / G for j in range(1, 8)])])
    for k in range(6):
        assert abs(traj.t[rows[k]] - exact[k]) <= 3 * (k + 1) * h, k
    for k in range(1, 6):
        apex = traj.q[rows[k - 1]:rows[k], 0].max()
        assert abs(apex - E**(2 * k) * H0) <= 1.5 * k * h * V0, k
    # the floor is only crossed within the impact steps: by at most h V0
    assert traj.saved["min_gap"].min() >= -h * V0


@pytest.mark.parametrize("h", [1e-3, 1e-4])
def test_bouncing_ball_comes_to_rest_at_the_accumulation_time(generated, h):
    """Rest (v = 0 from then on, to rounding) within 60 h after T_INF (measured: 25 h at
    h = 1e-3, 30 h at 1e-4: the last bounces, slower than a few g h, are not resolved).
    The last instant faster than 0.1 is just before the last impact with an incoming speed
    V in (0.1, 0.1 / e]; the bounces after it last 2 V / (g (1 - e)), so that instant lies in
    [T_INF - 0.2 / (e g (1 - e)), T_INF - 0.2 / (g (1 - e))], give or take the time error of
    the 17 impacts before it (3 h each, as above)."""
    traj = _ball(generated, h)
    v = traj.v[:, 0]
    moving = np.flatnonzero(np.abs(v) > 1e-12)
    t_rest = traj.t[moving[-1] + 1]
    assert T_INF - 2 * h <= t_rest <= T_INF + 60 * h
    fast = traj.t[np.flatnonzero(np.abs(v) > 0.1)[-1]]
    slack = 3 * 17 * h
    assert T_INF - 0.2 / (E * G * (1 - E)) - slack <= fast <= T_INF - 0.2 / (G * (1 - E)) + slack
    assert abs(traj.q[-1, 0]) <= h * V0 and traj.saved["active_contacts"][-1, 0] == 1


def test_bouncing_ball_energy_balance_closes(generated):
    """E - E0 - W_contact = 0: exact at theta = 1/2 for constant forces (rounding only)."""
    traj = _ball(generated, 1e-3)
    residual = traj.energy - traj.energy[0] - traj.saved["contact_work"][:, 0]
    assert np.abs(residual).max() <= 1e-11 * G * H0
    # The impacts dissipate. An impulse in a step that began opening (u- in (0, g h], in the
    # last bounces before rest) does the work p u- / 2 <= m (g h)^2 (measured once, 1.1e-5 at
    # h = 1e-3): the impulse acts on v+, and q+ moves with (v + v+) / 2.
    h = 1e-3
    assert np.all(np.diff(traj.saved["contact_work"][:, 0]) <= (G * h) ** 2)
    # at rest all the energy above the floor went into the impacts
    assert traj.saved["contact_work"][-1, 0] == pytest.approx(-G * H0, abs=G * h * V0)


def _ramp(generated, mu, a=0.5, h=1e-3, t_end=2.0):
    traj = simulate(generated("block_on_ramp"), method="moreau_jean", q0=[0.0, 0.0],
                    v0=[0.0, 0.0], t_end=t_end, h=h, params={"a": a, "mu": mu, "g": G})
    X, Y = traj.q[:, 0], traj.q[:, 1]
    return traj, X * math.cos(a) - Y * math.sin(a), X * math.sin(a) + Y * math.cos(a)


def test_block_on_ramp_slides_with_the_coulomb_acceleration(generated):
    a, mu = 0.5, 0.3           # tan a = 0.546 > mu
    traj, s, gap = _ramp(generated, mu, a)
    accel = G * (math.sin(a) - mu * math.cos(a))
    np.testing.assert_allclose(s, accel * traj.t**2 / 2, rtol=1e-10, atol=1e-13)
    assert np.abs(gap).max() <= 1e-12
    # sliding: the friction impulse sits on the cone's edge, mu p_N, against the motion
    pn, pt = traj.saved["normal_impulse"][1:, 0], traj.saved["tangent_impulse"][1:, 0]
    np.testing.assert_allclose(pt, -mu * pn, rtol=1e-12)
    np.testing.assert_allclose(pn, G * math.cos(a) * 1e-3, rtol=1e-10)
    residual = traj.energy - traj.energy[0] - traj.saved["contact_work"][:, 0]
    assert np.abs(residual).max() <= 1e-11 * G * s[-1]


def test_block_on_ramp_sticks_below_the_friction_angle(generated):
    a, mu = 0.5, 0.7           # tan a = 0.546 < mu
    traj, s, gap = _ramp(generated, mu, a)
    assert np.abs(s).max() <= 1e-15 and np.abs(gap).max() <= 1e-15
    pn, pt = traj.saved["normal_impulse"][1:, 0], traj.saved["tangent_impulse"][1:, 0]
    np.testing.assert_allclose(pt, -G * math.sin(a) * 1e-3, rtol=1e-10)
    assert np.all(np.abs(pt) < mu * pn)


def test_contact_problem_gauss_seidel_leaves_is_answered_by_lemke(generated):
    """One Gauss-Seidel sweep is too few for a sliding block (the normal and the tangential
    impulse need a second sweep to be seen unchanged); Lemke's method (core/contact_lcp.py)
    then answers, with the impulses of the converged sweeps (2D friction: the LCP is exact)."""
    runs = [simulate(generated("block_on_ramp"), method="moreau_jean", q0=[0.0, 0.0], t_end=0.01,
                     h=1e-3, **options) for options in ({}, {"max_sweeps": 1})]
    for field in ("normal_impulse", "tangent_impulse"):
        np.testing.assert_allclose(runs[1].saved[field], runs[0].saved[field], rtol=1e-9,
                                   atol=1e-15)
    np.testing.assert_allclose(runs[1].q, runs[0].q, rtol=1e-9, atol=1e-15)


@pytest.mark.parametrize("method", ["verlet", "implicit_euler"])
def test_other_methods_refuse_a_model_with_contacts(generated, method):
    with pytest.raises(SimulationError, match=r"ignores the model's unilateral contacts.*moreau_jean"):
        simulate(generated("bouncing_ball"), method=method, q0=[1.0], t_end=0.1, h=1e-3)


def test_moreau_jean_refuses_a_model_without_contacts(generated):
    with pytest.raises(SimulationError, match=r"moreau_jean.*unilateral contacts and this model has none"):
        simulate(generated("damped_oscillator"), method="moreau_jean", q0=[1.0], t_end=0.1, h=1e-3)


@pytest.mark.parametrize("model, params, message", [
    ("bouncing_ball", {"e": 1.5},
     r"bouncing_ball: contact 'floor': restitution = 1.5 must be in \[0, 1\]; it depends on "
     r"e = 1.5"),
    ("bouncing_ball", {"e": -0.2}, r"restitution = -0.2 must be in \[0, 1\]"),
    ("block_on_ramp", {"mu": -0.1},
     r"block_on_ramp: contact 'ramp': friction = -0.1 must be >= 0; it depends on mu = -0.1"),
])
def test_coefficients_given_by_parameters_are_checked_at_run_time(generated, model, params,
                                                                  message):
    """The model file checks the coefficients at the parameters' defaults; params= can override
    them, so simulate checks them again before it runs: one line naming contact and parameter."""
    module = generated(model)
    n = module.N_COORDS
    with pytest.raises(SimulationError, match=message) as info:
        simulate(module, method="moreau_jean", q0=[0.5] * n, t_end=0.01, h=1e-3, params=params)
    assert "\n" not in str(info.value)


def test_ensemble_checks_each_members_coefficients(generated):
    from lagrange_gen.run.ensemble import ensemble
    with pytest.raises(SimulationError, match=r"restitution = 1.5 must be in \[0, 1\]"):
        ensemble(generated("bouncing_ball"), method="moreau_jean", q0=[[1.0], [1.0]],
                 t_end=0.01, h=1e-3, params={"e": [0.5, 1.5]})
