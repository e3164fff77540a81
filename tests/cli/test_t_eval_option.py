"""--t-eval takes times and ranges START:STOP:STEP (STOP included when a step lands on it);
junk is one error line naming the option and the item."""

import numpy as np
import pytest

from lagrange_gen.cli.main import main
from lagrange_gen.cli.options import parse_times
from lagrange_gen.errors import LagrangeGenError
from lagrange_gen.run.trajectory import Trajectory


@pytest.mark.parametrize("values, expected", [
    (["0:1:0.25"], [0, 0.25, 0.5, 0.75, 1.0]),
    (["0:0.3:0.1"], [0, 0.1, 0.2, 0.3]),          # 0.3 / 0.1 = 2.9999999999999996
    (["0:1:0.3"], [0, 0.3, 0.6, 0.9]),
    (["0.5", "1", "2:3:0.5"], [0.5, 1, 2, 2.5, 3]),
    (["1e-3"], [1e-3]),
    (["2:2:0.1"], [2.0]),
])
def test_times_and_ranges(values, expected):
    np.testing.assert_allclose(parse_times(values, "--t-eval"), expected, rtol=0, atol=1e-15)


@pytest.mark.parametrize("junk", ["abc", "0:1", "0:1:0", "0:1:-0.1", "1:0:0.1", "0:1:x",
                                  "nan", "0:inf:1", "0:1:1:1", "0:10:100"])
def test_junk_is_one_line_naming_the_option_and_item(junk):
    with pytest.raises(LagrangeGenError) as info:
        parse_times(["0", junk], "--t-eval")
    message = str(info.value)
    assert message.startswith(f"--t-eval {junk}:") and "\n" not in message


def test_cli_run_saves_the_range(generated, tmp_path, capsys):
    module = generated("bouncing_ball")
    out = tmp_path / "ball.npz"
    assert main(["simulate", module.__file__, "--method", "dop853_impacts", "--q0", "1",
                 "--t-end", "1", "--t-eval", "0:1:0.25", "--out", str(out)]) == 0
    np.testing.assert_allclose(Trajectory.load(out).t, [0, 0.25, 0.5, 0.75, 1.0])


def test_cli_junk_exits_with_one_line(generated, capsys):
    module = generated("bouncing_ball")
    assert main(["simulate", module.__file__, "--method", "dop853_impacts", "--t-end", "1",
                 "--t-eval", "0:1"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("lagrange-gen: error: --t-eval 0:1:") and "\n" not in err
