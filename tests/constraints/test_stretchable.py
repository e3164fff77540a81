"""HARD_CASES case 7: the stretchable pendulum (bob on a spring of stiffness k) at fixed h as k goes
from 1e2 to 1e8. Implicit Euler (on the spring model) and spook (on the rigid model with
compliance 1/k) stay bounded and approach the rigid pendulum integrated by rattle; verlet is
stable for h omega < 2 and its blow-up beyond is reported as BlowUp, not returned silently."""

import numpy as np
import pytest

from constraint_util import generated_model, pendulum_state
from lagrange_gen.errors import BlowUp
from lagrange_gen.run.simulate import simulate

H, T_END, THETA0, G = 1e-3, 2.0, 1.0, 9.81
STIFFNESS = (1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8)


def spring_start(k):
    """Released at rest at THETA0 with the spring at its static stretch (stiff mode at rest)."""
    return pendulum_state(THETA0, 0.0, l=1.0 + G * np.cos(THETA0) / k)


@pytest.fixture(scope="module")
def rigid():
    """The rigid pendulum in Cartesian coordinates with rattle at the same h (reference)."""
    q0, v0 = pendulum_state(THETA0, 0.0)
    return simulate(generated_model("cartesian_pendulum"), "rattle", q0, v0, t_end=T_END, h=H)


def _distances(runs, rigid):
    return np.array([np.abs(traj.q - rigid.q).max() for traj in runs])


def _assert_converges(dist, floor):
    """Monotone approach (within 5 %) to a plateau at the method's own O(h) error."""
    assert np.all(np.isfinite(dist))
    assert np.all(dist[1:] <= 1.05 * dist[:-1]), dist
    assert dist[0] > 10 * dist[-1], dist
    assert dist[-1] < floor, dist
    assert abs(dist[-1] - dist[-2]) < 0.05 * dist[-1], dist     # converged in k


def test_implicit_euler_bounded_and_converges_to_rigid(rigid):
    mod = generated_model("stretchable_pendulum")
    runs = []
    for k in STIFFNESS:
        q0, v0 = spring_start(k)
        runs.append(simulate(mod, "implicit_euler", q0, v0, t_end=T_END, h=H, params={"k": k}))
    dist = _distances(runs, rigid)
    _assert_converges(dist, floor=20 * H)
    # The spring's stretch |r - l| falls like 1/k (the bob approaches the circle).
    stretch = [np.abs(np.hypot(*traj.q.T) - 1.0).max() for traj in runs]
    assert stretch[-1] < 1e-6 and stretch[0] > 1e4 * stretch[-1], stretch
    # What is left at k = 1e8 is implicit Euler's O(h) error: halving h halves it.
    q0, v0 = spring_start(1e8)
    finer = simulate(mod, "implicit_euler", q0, v0, t_end=T_END, h=H / 2, params={"k": 1e8})
    q_rigid_end = rigid.q[-1]
    ratio = np.abs(runs[-1].q[-1] - q_rigid_end).max() / np.abs(finer.q[-1] - q_rigid_end).max()
    assert 1.6 < ratio < 2.6, ratio


def test_spook_bounded_and_converges_to_rigid(rigid):
    """spook with compliance 1/k on the rigid model is the spring of stiffness k (to first order
    in the stretch). As k grows it tends to spook with compliance 0 (distance falling like 1/k),
    which is within O(h) of rattle; every run stays bounded."""
    mod = generated_model("cartesian_pendulum")
    q0, v0 = pendulum_state(THETA0, 0.0)
    runs = [simulate(mod, "spook", q0, v0, t_end=T_END, h=H, compliance=1.0 / k)
            for k in STIFFNESS]
    limit = simulate(mod, "spook", q0, v0, t_end=T_END, h=H, compliance=0.0)
    to_limit = _distances(runs, limit)
    assert np.all(np.isfinite(to_limit))
    assert np.all(to_limit[1:] < 0.5 * to_limit[:-1]), to_limit
    assert to_limit[-1] < 1e-6, to_limit
    to_rigid = _distances(runs, rigid)
    assert to_rigid[0] > 100 * to_rigid[-1] and to_rigid[-1] < 5 * H, to_rigid
    assert np.abs(limit.q - rigid.q).max() < 5 * H


@pytest.mark.parametrize("tau", [1.0, 1.9])
def test_verlet_stable_below_tau_2(rigid, tau):
    k = (tau / H) ** 2          # m = 1: omega = sqrt(k)
    q0, v0 = spring_start(k)
    traj = simulate(generated_model("stretchable_pendulum"), "verlet", q0, v0, t_end=T_END, h=H,
                    params={"k": k})
    assert np.abs(traj.q - rigid.q).max() < 1e-3


@pytest.mark.parametrize("tau", [2.1, 10.0])
def test_verlet_blow_up_beyond_tau_2_is_reported(tau):
    k = (tau / H) ** 2
    q0, v0 = spring_start(k)
    with pytest.raises(BlowUp, match=r"step \d+ of 2000 \(t = .*blow-up bound") as info:
        simulate(generated_model("stretchable_pendulum"), "verlet", q0, v0, t_end=T_END, h=H,
                 params={"k": k})
    assert 1 <= info.value.step < 2000
