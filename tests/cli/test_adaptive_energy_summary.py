"""An adaptive run of a damped model: the work W of damping, forces and explicit time is not
integrated by the adaptive loop, and the summary, Trajectory.energy_balance and the plot say so
instead of passing E - E0 off as the balance; the plot's title gives the tolerances, not a mean
step."""

import math
import warnings
from pathlib import Path

import numpy as np
import pytest

import lagrange_gen as lg
from lagrange_gen.cli.main import main

DAMPED = Path(__file__).resolve().parents[2] / "generated" / "damped_oscillator.py"
RUN = dict(q0=[1.0], t_end=2.0, params={"b": 0.5})


@pytest.fixture(scope="module")
def adaptive():
    return lg.simulate(DAMPED, "dop853", rtol=1e-8, atol=1e-10, **RUN)


def test_the_trajectory_says_w_is_not_tracked_and_energy_balance_warns(adaptive):
    assert adaptive.work is None
    assert "not tracked" in adaptive.work_note and "dop853" in adaptive.work_note
    with pytest.warns(UserWarning, match="not tracked"):
        balance = adaptive.energy_balance
    # what it returns is E - E0, far from zero on a damped run (the energy lost to damping)
    np.testing.assert_array_equal(balance, adaptive.energy - adaptive.energy[0])
    assert adaptive.max_energy_error > 0.1


def test_a_fixed_step_run_tracks_w_and_says_nothing():
    traj = lg.simulate(DAMPED, "rk4", h=1e-2, **RUN)
    assert traj.work_note == "" and traj.work is not None
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert traj.max_energy_balance_error < 1e-6


def test_the_summary_says_w_is_not_tracked(capsys):
    args = ["simulate", str(DAMPED), "--method", "dop853", "--q0", "1", "--t-end", "2",
            "--param", "b=0.5", "--rtol", "1e-8"]
    assert main(args) == 0
    out = capsys.readouterr().out
    line = next(s for s in out.splitlines() if s.startswith("max |E - E0|"))
    assert "W not tracked" in line and "fixed-step" in line


def test_the_plot_title_gives_the_tolerances_and_the_energy_panel_says_e_minus_e0(adaptive):
    fig = adaptive.plot()
    title = fig.get_suptitle()
    assert "adaptive, rtol=1e-08, atol=1e-10" in title and "h =" not in title
    labels = [ax.get_ylabel() for ax in fig.axes]
    assert "E - E0 (W not tracked)" in labels


def test_the_note_and_the_settings_survive_a_file(adaptive, tmp_path):
    adaptive.to_npz(tmp_path / "run.npz")
    back = lg.Trajectory.load(tmp_path / "run.npz")
    assert back.work_note == adaptive.work_note
    assert math.isclose(back.settings["rtol"], 1e-8)
