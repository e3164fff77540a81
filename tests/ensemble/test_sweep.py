"""`lagrange-gen sweep`: the npz holds the ensemble over the grid and the chosen scalar, equal to
lagrange_gen.ensemble called directly; bad grid options are one line and exit 2."""

from pathlib import Path

import numpy as np
import pytest

import lagrange_gen as lg
from lagrange_gen.cli.main import main
from lagrange_gen.cli.sweep import parse_axis

MODEL = Path(__file__).resolve().parents[2] / "models" / "cart_pendulum.py"


def test_sweep_writes_the_grid_ensemble_and_its_picture(tmp_path, capsys):
    gen, out, png = tmp_path / "gen", tmp_path / "sweep.npz", tmp_path / "sweep.png"
    code = main(["sweep", str(MODEL), "--method", "rk4", "--grid", "k=5:15:3",
                 "--grid", "m=0.2,0.6", "--q0", "0.1", "0", "--v0", "0", "1", "--param", "g=9.8",
                 "--t-end", "0.2", "--h", "0.01", "--save-every", "5", "--scalar",
                 "max_amplitude", "--coord", "theta", "--gen-dir", str(gen), "--out", str(out),
                 "--plot", str(png)])
    assert code == 0 and png.stat().st_size > 0
    assert "6 members over k (3) x m (2), 0 failed" in capsys.readouterr().out
    data = np.load(out)
    assert data["grid_names"].tolist() == ["k", "m"] and data["axis_k"].tolist() == [5, 10, 15]
    direct = lg.ensemble(gen / "cart_pendulum.py", "rk4", q0=[0.1, 0.0], v0=[0.0, 1.0],
                         params={"g": 9.8, **lg.grid(k=[5, 10, 15], m=[0.2, 0.6])}, t_end=0.2,
                         h=0.01, save_every=5)
    np.testing.assert_array_equal(data["q"], direct.q)
    np.testing.assert_array_equal(data["scalar"], np.abs(direct.q[:, :, 1]).max(axis=1))
    assert len(set(data["scalar"].tolist())) == 6       # every grid point moves differently


@pytest.mark.parametrize("options, message", [
    (["--grid", "k=1:2"], "--grid k=1:2: expected NAME=START:STOP:COUNT"),
    (["--grid", "k=1:2:3", "--param", "k=4"], "parameter 'k' is given both by --grid and --param"),
    (["--grid", "k=1:2:2", "--grid", "m=1:2:2", "--grid", "g=9:10:2", "--plot", "x.png"],
     "--plot pictures one or two grid axes; 3 given"),
])
def test_bad_sweep_options_are_one_line(tmp_path, capsys, options, message):
    code = main(["sweep", str(MODEL), "--t-end", "0.1", "--h", "0.01", "--gen-dir",
                 str(tmp_path), *options])
    err = capsys.readouterr().err
    assert code == 2 and message in err and err.count("\n") == 1


def test_parse_axis_includes_both_ends():
    name, values = parse_axis("c=0:1:5")
    assert name == "c" and values.tolist() == [0, 0.25, 0.5, 0.75, 1.0]
