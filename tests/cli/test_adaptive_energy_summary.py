"""An adaptive run of a damped model integrates the work W of damping, forces and explicit time
like a fixed-step run: the Trajectory has it, energy_balance is E - E0 - W without a warning,
the summary prints max |E - E0 - W| with the final W, the plot draws E - E0 - W; the plot's
title gives the tolerances, not a mean step."""

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


def test_the_trajectory_has_w_and_energy_balance_closes_without_a_warning(adaptive):
    assert adaptive.work is not None and adaptive.work[0] == 0.0
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        balance = adaptive.energy_balance
    # E - E0 is far from zero on a damped run (the energy lost to damping); W accounts for it
    assert adaptive.max_energy_error > 0.1
    assert np.abs(balance).max() < 1e-8
    np.testing.assert_allclose(adaptive.work, adaptive.energy - adaptive.energy[0], atol=1e-8)


def test_a_fixed_step_run_tracks_w_the_same_way():
    traj = lg.simulate(DAMPED, "rk4", h=1e-2, **RUN)
    assert traj.work is not None
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert traj.max_energy_balance_error < 1e-6


def test_the_summary_gives_the_balance_with_w(capsys):
    args = ["simulate", str(DAMPED), "--method", "dop853", "--q0", "1", "--t-end", "2",
            "--param", "b=0.5", "--rtol", "1e-8"]
    assert main(args) == 0
    out = capsys.readouterr().out
    line = next(s for s in out.splitlines() if s.startswith("max |E - E0"))
    assert line.startswith("max |E - E0 - W| = ") and "final W = " in line
    assert float(line.split("= ")[1].split()[0]) < 1e-7
    assert "not tracked" not in out


def test_the_plot_title_gives_the_tolerances_and_the_energy_panel_the_balance(adaptive):
    fig = adaptive.plot()
    title = fig.get_suptitle()
    assert "adaptive, rtol=1e-08, atol=1e-10" in title and "h =" not in title
    labels = [ax.get_ylabel() for ax in fig.axes]
    assert "E - E0 - W" in labels


def test_the_work_and_the_settings_survive_a_file(adaptive, tmp_path):
    adaptive.to_npz(tmp_path / "run.npz")
    back = lg.Trajectory.load(tmp_path / "run.npz")
    np.testing.assert_array_equal(back.work, adaptive.work)
    assert math.isclose(back.settings["rtol"], 1e-8)
