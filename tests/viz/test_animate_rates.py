"""The frame rate and resolution of an animation: a rate or resolution that is not a finite
number > 0 (`--fps nan`, `inf`, 0, negative) is one line and exit 2 from `lagrange-gen animate`,
a LagrangeGenError from Trajectory.animate, before anything is written."""

import math

import pytest

from lagrange_gen.cli.main import main
from lagrange_gen.errors import LagrangeGenError


@pytest.mark.parametrize("fps", ["nan", "inf", "-inf", "0", "-2", "1e400"])
def test_cli_refuses_a_frame_rate_that_is_not_a_finite_positive_number(run, tmp_path, capsys, fps):
    run("pendulum").save(tmp_path / "dp.npz")
    capsys.readouterr()                     # (the run's compile notice)
    assert main(["animate", str(tmp_path / "dp.npz"), f"--fps={fps}", "--frames", "2"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert "--fps" in err and "finite number > 0" in err
    assert not (tmp_path / "dp.gif").exists()


@pytest.mark.parametrize("dpi", ["0", "-30"])
def test_cli_refuses_a_resolution_that_is_not_positive(run, tmp_path, capsys, dpi):
    run("pendulum").save(tmp_path / "dp.npz")
    capsys.readouterr()                     # (the run's compile notice)
    assert main(["animate", str(tmp_path / "dp.npz"), f"--dpi={dpi}", "--frames", "2"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--dpi" in err and "Traceback" not in err
    assert not (tmp_path / "dp.gif").exists()


@pytest.mark.parametrize("fps", [math.nan, math.inf, 0.0, -1.0, "25", True])
def test_trajectory_animate_refuses_it_in_one_line(run, tmp_path, fps):
    with pytest.raises(LagrangeGenError) as info:
        run("pendulum").animate(tmp_path / "x.gif", frames=2, fps=fps)
    assert "\n" not in str(info.value) and "fps" in str(info.value)
    assert not (tmp_path / "x.gif").exists()
