"""Newton's cradle (models/newtons_cradle.py) under moreau_jean: simultaneous and separate
impacts of three equal balls (mass m, radius r) on a line, against closed forms.

Simultaneous: ball 1 at speed V hits balls 2 and 3, which touch at rest. Moreau-Jean puts both
contacts in the step's index set and solves Newton's law on both at once: with impulses p1
(balls 1-2) and p2 (balls 2-3), v+ = (V - p1/m, (p1 - p2)/m, p2/m); the relative velocities
after are u1 = v2 - v1 = (2 p1 - p2)/m - V and u2 = v3 - v2 = (2 p2 - p1)/m, and
complementarity with both impulses positive gives u1 = e V, u2 = 0 (u2 was 0 before), so
p2 = (1 + e) m V / 3, p1 = 2 p2, and

    v+ = ((1 - 2e) V / 3, (1 + e) V / 3, (1 + e) V / 3),   T+ / T- = (1 + 2 e^2) / 3.

At e = 1: (-V/3, 2V/3, 2V/3), energy conserved, not the toy's (0, 0, V) (which a sequential
impact law gives). Separate (e = 1, balls 2 and 3 apart): two impacts, each exchanging the
velocities of equal masses: (0, 0, V) after ball 2 has crossed the gap between 2 and 3.

Tolerances: no force acts between impacts, so the free steps are exact; the velocities after an
impact come from the contact problem, solved by projected Gauss-Seidel to contact_tol = 1e-10
relative change per sweep (its error contracts by 1/4 per sweep here, D = [[2, -1], [-1, 2]] / m,
so it is below 1e-9 V). An impact acts over the step in which the free motion would close the
gap: positions move with (v + v+)/2 in it, as if the impact were at mid-step, so each impact
time is off by at most h/2 and each position by h/2 |change of v| per impact. Momentum is exact
to rounding (the impulses act in equal and opposite pairs), as is the energy balance
E - E0 - W_contact at theta = 1/2 without forces.
"""

import numpy as np
import pytest

from lagrange_gen.run.simulate import simulate

R, V, H, T_END = 0.1, 1.0, 1e-3, 1.0
GAP = 0.0537         # ball 1's gap to ball 2 (off the grid of steps: no tie at a step's end)


def _run(generated, q0, e):
    return simulate(generated("newtons_cradle"), method="moreau_jean", q0=q0, v0=[V, 0.0, 0.0],
                    t_end=T_END, h=H, params={"r": R, "e": e})


@pytest.mark.parametrize("e", [1.0, 0.5, 0.0])
def test_simultaneous_impact_of_three_touching_balls(generated, e):
    q0 = np.array([0.0, 2 * R + GAP, 4 * R + GAP])
    traj = _run(generated, q0, e)
    after = np.array([(1 - 2 * e) * V / 3, (1 + e) * V / 3, (1 + e) * V / 3])
    np.testing.assert_allclose(traj.v[-1], after, rtol=0, atol=1e-9 * V)
    t_impact = GAP / V
    exact = q0 + V * np.array([t_impact, 0.0, 0.0]) + after * (T_END - t_impact)
    assert np.abs(traj.q[-1] - exact).max() <= H / 2 * np.abs(after - [V, 0, 0]).max() + 1e-12
    # both contacts took an impulse in the same step: one impact, two contacts
    impulses = traj.saved["normal_impulse"]
    rows = np.flatnonzero(impulses.max(axis=1) > 0)
    assert len(rows) == 1 and traj.saved["active_contacts"][rows[0], 0] == 2
    np.testing.assert_allclose(impulses[rows[0]], [2 * (1 + e) * V / 3, (1 + e) * V / 3],
                               rtol=1e-9)
    np.testing.assert_allclose(traj.v.sum(axis=1), V, rtol=0, atol=1e-14)      # momentum (m = 1)
    T_ratio = traj.energy[-1] / traj.energy[0]
    assert T_ratio == pytest.approx((1 + 2 * e**2) / 3, abs=2e-9)
    residual = traj.energy - traj.energy[0] - traj.saved["contact_work"][:, 0]
    assert np.abs(residual).max() <= 1e-14


def test_separate_impacts_pass_the_velocity_down_the_chain(generated):
    gap_23 = 0.1213
    q0 = np.array([0.0, 2 * R + GAP, 4 * R + GAP + gap_23])
    traj = _run(generated, q0, 1.0)
    np.testing.assert_allclose(traj.v[-1], [0.0, 0.0, V], rtol=0, atol=1e-12)
    t1, t2 = GAP / V, (GAP + gap_23) / V
    exact = q0 + V * np.array([t1, t2 - t1, T_END - t2])
    assert np.abs(traj.q[-1] - exact).max() <= H / 2 * V + 1e-12
    impulses = traj.saved["normal_impulse"]
    assert len(np.flatnonzero(impulses.max(axis=1) > 0)) == 2        # two steps, one contact each
    assert traj.energy[-1] == pytest.approx(traj.energy[0], rel=1e-12)
    np.testing.assert_allclose(traj.v.sum(axis=1), V, rtol=0, atol=1e-14)
