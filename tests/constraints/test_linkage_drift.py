"""HARD_CASES case 8: the closed-loop four-bar linkage over 1e5 steps. The projected methods keep
|Phi| and |J v| at the Newton tolerance at every saved step; the index-1 (acceleration-level)
formulation, integrated by rk4, drifts off the manifold and keeps drifting."""

import numpy as np
import pytest

from constraint_util import four_bar_state, generated_model
from lagrange_gen.run.simulate import simulate

N_STEPS, H = 100_000, 1e-3
TOL = 1e-12     # simulate's default newton_tol


@pytest.fixture(scope="module")
def linkage():
    """The swinging linkage (crank released at rest at 0.3 rad; it swings between about -3.8 and
    0.3 rad, so |q| stays O(1) and the tolerance is absolute), one trajectory per method."""
    mod = generated_model("four_bar")
    q0, v0 = four_bar_state(0.3, 0.0)
    runs = {}

    def get(method):
        if method not in runs:
            runs[method] = simulate(mod, method, q0, v0, t_end=N_STEPS * H, h=H, save_every=10)
        return runs[method]
    return get


@pytest.mark.parametrize("method", ["rattle", "constrained_midpoint", "constrained_implicit_euler"])
def test_projected_methods_stay_on_the_manifold(linkage, method):
    traj = linkage(method)
    scale = max(1.0, np.abs(traj.q).max())
    assert traj.n_steps == N_STEPS
    assert traj.constraint_error.max() <= TOL * scale, traj.constraint_error.max()
    assert traj.velocity_constraint_error.max() <= TOL * scale, traj.velocity_constraint_error.max()
    # No growth either: the last tenth is at the level of the first.
    tenth = len(traj.t) // 10
    first = max(traj.constraint_error[:tenth].max(), 1e-15)
    assert traj.constraint_error[-tenth:].max() <= 10 * first


def test_index1_drifts_where_rattle_does_not(linkage):
    """Same initial state and step: index1's |Phi| is orders of magnitude above rattle's and
    grows over the run (last tenth >= 20 x first tenth), as does |J v|."""
    bad, good = linkage("index1"), linkage("rattle")
    tenth = len(bad.t) // 10
    first, last = bad.constraint_error[:tenth].max(), bad.constraint_error[-tenth:].max()
    assert last >= 20 * first, (first, last)
    assert bad.constraint_error.max() >= 1e4 * good.constraint_error.max()
    assert bad.constraint_error.max() > 1e3 * TOL
    jv_first = bad.velocity_constraint_error[:tenth].max()
    assert bad.velocity_constraint_error[-tenth:].max() >= 5 * jv_first
    # The motion itself is still right (rk4 is accurate): the drift is the point, not the error.
    assert np.abs(bad.q[-1] - good.q[-1]).max() < 1e-2


def test_baumgarte_bounds_index1_drift(linkage):
    """index1 with Baumgarte's stabilization (alpha = beta = 10 /s): |Phi| stays bounded (no growth
    between the first and the last tenth) and far below the unstabilized drift -- still far
    above the projected methods' round-off."""
    mod = generated_model("four_bar")
    q0, v0 = four_bar_state(0.3, 0.0)
    stab = simulate(mod, "index1", q0, v0, t_end=N_STEPS * H, h=H, save_every=10,
                    baumgarte=(10.0, 10.0))
    tenth = len(stab.t) // 10
    assert stab.constraint_error[-tenth:].max() <= 2 * stab.constraint_error[:tenth].max()
    assert stab.constraint_error.max() < 1e-2 * linkage("index1").constraint_error.max()
    assert stab.constraint_error.max() > 100 * linkage("rattle").constraint_error.max()
