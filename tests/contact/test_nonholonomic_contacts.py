"""Velocity constraints beside contacts (models/sleigh_drop.py): moreau_jean treats the knife
edge's no-sideslip row and the floor together. The sleigh's horizontal motion and the bounce do
not couple, so each is checked against its own reference: the sleigh's reduced equations
(Bloch sec. 1.7, integrated by scipy, never through derive/) and the bouncing ball's closed form."""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import lagrange_gen as lg
from lagrange_gen.errors import SimulationError
from lagrange_gen.steppers.core import registry

M, I, A, G, E = 1.0, 0.2, 0.5, 9.81, 0.5       # models/sleigh_drop.py's defaults
Z0, TH0, U0, W0 = 1.0, 0.3, 1.0, 2.0            # height, heading, forward and turning speed
T_END = 1.2


def _start():
    """(q0, v0) on the constraint: the centre of mass moves at u along the heading plus a w
    sideways (no sideslip at the knife edge)."""
    q0 = np.array([0.0, 0.0, Z0, TH0])
    v0 = np.array([U0 * np.cos(TH0) - A * W0 * np.sin(TH0), U0 * np.sin(TH0) + A * W0 * np.cos(TH0),
                   0.0, W0])
    return q0, v0


def _sleigh_reference():
    """Dense (x, y, theta, u, w)(t) of the Chaplygin sleigh: u' = a w^2, w' = -m a u w / (I + m a^2)."""
    def rhs(t, s):
        x, y, th, u, w = s
        return [u * np.cos(th) - A * w * np.sin(th), u * np.sin(th) + A * w * np.cos(th), w,
                A * w * w, -M * A * u * w / (I + M * A * A)]
    return solve_ivp(rhs, (0.0, T_END), [0.0, 0.0, TH0, U0, W0], rtol=1e-12, atol=1e-12,
                     dense_output=True).sol


@pytest.fixture(scope="module")
def runs(generated):
    mod = generated("sleigh_drop")
    q0, v0 = _start()
    return mod, {h: lg.simulate(mod, "moreau_jean", q0, v0, t_end=T_END, h=h)
                 for h in (4e-3, 2e-3, 1e-3)}


def test_only_moreau_jean_runs_a_velocity_constraint_beside_a_contact(generated):
    mod = generated("sleigh_drop")
    assert mod.METHODS == ("moreau_jean",)
    assert registry.applicable_methods(0, 0, 1, 1) == ("moreau_jean",)
    q0, v0 = _start()
    for method, why in (("dop853_impacts", "does not treat nonholonomic constraints beside "
                                           "contacts \\(use moreau_jean\\)"),
                        ("nonholonomic_midpoint", "ignores the model's unilateral contacts "
                                                  "\\(use moreau_jean\\)")):
        with pytest.raises(SimulationError, match=why):
            lg.simulate(mod, method, q0, v0, t_end=0.01, h=1e-3)


def test_the_sleigh_moves_as_on_the_ground_while_it_bounces(runs):
    """First order (the row A is taken at the step's start configuration, as the contact rows),
    towards the sleigh's reduced equations."""
    _, by_h = runs
    ref = _sleigh_reference()
    errors = []
    for h, traj in by_h.items():
        r = ref(traj.t)
        errors.append(max(np.abs(traj.q[:, 0] - r[0]).max(), np.abs(traj.q[:, 1] - r[1]).max(),
                          np.abs(traj.q[:, 3] - r[2]).max()))
    hs = np.array(list(by_h))
    order = np.polyfit(np.log(hs), np.log(errors), 1)[0]
    assert 0.9 < order < 1.2, (order, errors)
    assert errors[-1] < 2e-3, errors


def test_the_knife_edge_force_is_the_sleighs(runs):
    """The saved multiplier is the sideways force at the knife edge: M qdd = f + A^T mu with
    I theta'' = -a mu, so mu = I m u w / (I + m a^2) along the reference motion. A step's row A
    is the one of its start configuration, which the velocity left by the step before met: the
    impulse of step k turns the velocity by what A turned in step k - 1, so the multiplier saved
    after step k (k >= 2) is the force at t_(k-1), and the first step needs none (no
    horizontal force)."""
    _, by_h = runs
    ref = _sleigh_reference()
    misses = []
    for h, traj in by_h.items():
        assert traj.saved["nonholonomic_multipliers"][1, 0] == 0.0
        r = ref(traj.t[1:-1])
        mu = I * M * r[3] * r[4] / (I + M * A * A)
        misses.append(np.abs(traj.saved["nonholonomic_multipliers"][2:, 0] - mu).max())
    assert misses[-1] < 0.02 and misses[0] / misses[-1] > 2.5, misses


def test_the_bounce_is_the_bouncing_balls(runs):
    """The first impact at sqrt(2 z0 / g) and the rebound to e^2 z0, each to O(h)."""
    _, by_h = runs
    t1 = np.sqrt(2 * Z0 / G)
    for h, traj in by_h.items():
        first = traj.t[np.argmax(traj.saved["active_contacts"][:, 0] > 0)]
        assert abs(first - t1) <= 2 * h, (h, first, t1)
        rebound = traj.q[traj.t > t1 + 0.05, 2].max()
        assert abs(rebound - E * E * Z0) <= 8 * h, (h, rebound)
        assert traj.saved["min_gap"][:, 0].min() > -2 * h * np.sqrt(2 * G * Z0)


def test_the_velocity_constraint_holds_to_first_order(runs):
    """A v + b = 0 holds exactly for the configuration the step starts from; at the step's end
    it is off by O(h), not growing."""
    _, by_h = runs
    worst = [traj.saved["nonholonomic_error"].max() for traj in by_h.values()]
    assert worst[-1] < 3e-3 and worst[0] / worst[-1] > 3.0, worst
    for traj in by_h.values():
        error, third = traj.saved["nonholonomic_error"][:, 0], len(traj.t) // 3
        assert error[-third:].max() <= error[:third].max()
