"""Events through simulate() with the adaptive dop853 (located on its dense output) and a
fixed-step method: times against scipy's DOP853 event location and a closed form, terminal
stops, and the rows of a run that a terminal event ends."""

import math

import numpy as np
import pytest

from lagrange_gen.run.simulate import simulate
from test_event_reference import scipy_events

MODELS = __import__("events_util").MODELS


@pytest.fixture(scope="module")
def gen_dir(tmp_path_factory):
    return tmp_path_factory.mktemp("adaptive_events")


def test_dop853_event_times_match_scipy_to_1e9(gen_dir):
    q0, v0, t_end = np.array([0.1, 0.5]), np.zeros(2), 3.0
    traj = simulate(MODELS / "cart_pendulum_events.py", "dop853", q0, v0, t_end=t_end,
                    out_dir=gen_dir, rtol=1e-12, atol=1e-12)
    from lagrange_gen.run.simulate import load_module
    reference = scipy_events(load_module(MODELS / "cart_pendulum_events.py", gen_dir), q0, v0,
                             t_end)
    for name, times in reference.items():
        got = traj.events["t"][traj.events["name"] == name]
        assert len(times) >= 2 and len(got) == len(times), name
        np.testing.assert_allclose(got, times, rtol=0, atol=1e-9, err_msg=name)
    # The first pass of the bob through the vertical (the README's example).
    first = traj.events[traj.events["name"] == "vertical"][0]
    assert abs(first["t"] - reference["vertical"][0]) < 1e-9 and abs(first["q"][1]) < 1e-12


@pytest.mark.parametrize("method, extra", [("dop853", {}), ("rk4", {"h": 1e-3}),
                                           ("midpoint", {"h": 1e-3, "save_every": 7})])
def test_terminal_event_ends_the_run_at_the_impact(gen_dir, method, extra):
    """Free fall from rest at height 1: the ground at t* = sqrt(2 / g) ends the run there."""
    traj = simulate(MODELS / "falling_mass.py", method, [1.0], [0.0], t_end=3.0,
                    out_dir=gen_dir, **extra)
    t_star = math.sqrt(2.0 / 9.81)
    assert len(traj.events) == 1 and traj.events[0]["name"] == "ground"
    assert abs(traj.events[0]["t"] - t_star) < 1e-10
    assert traj.t[-1] == traj.events[0]["t"] and abs(traj.q[-1, 0]) < 1e-10
    assert np.all(np.diff(traj.t) > 0) and traj.t[-2] < t_star


def test_terminal_event_with_t_eval_keeps_the_requested_times_before_it(gen_dir):
    t_eval = np.linspace(0.0, 3.0, 31)
    traj = simulate(MODELS / "falling_mass.py", "dop853", [1.0], [0.0], t_end=3.0,
                    out_dir=gen_dir, t_eval=t_eval, rtol=1e-12, atol=1e-12)
    t_star = math.sqrt(2.0 / 9.81)
    np.testing.assert_array_equal(traj.t, t_eval[t_eval <= t_star])
    np.testing.assert_allclose(traj.q[:, 0], 1.0 - 9.81 * traj.t**2 / 2, rtol=0, atol=1e-12)
