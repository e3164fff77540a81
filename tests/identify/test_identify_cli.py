"""`lagrange-gen identify DATA.csv ...` through the subcommand's add_parser / run."""

import argparse
import math
import re

import numpy as np
import pytest
from identify_cases import C, prandtl_run, steady_cycle  # noqa: F401 (fixtures)

from lagrange_gen.identify import IdentificationError
from lagrange_gen.identify.cli import add_parser, run


def _invoke(argv):
    parser = argparse.ArgumentParser(prog="lagrange-gen")
    add_parser(parser.add_subparsers(dest="command", required=True))
    return run(parser.parse_args(["identify"] + argv))


def test_prandtl_from_csv_with_header(tmp_path, steady_cycle, capsys):
    """One steady cycle, every 5th sample, columns x,F,v: the table shows k_i = 1/3, eta_i = i."""
    _, x, f, v = steady_cycle
    path = tmp_path / "cycle.csv"
    np.savetxt(path, np.column_stack([x, f, v])[::5], delimiter=",", header="x,F,v",
               comments="")
    assert _invoke([str(path), "--kind", "prandtl", "--elements", "3",
                    "--damping", str(C)]) == 0
    out = capsys.readouterr().out
    assert "3 element(s)" in out and "k0 = 0.333333" in out
    rows = [line.split() for line in out.splitlines() if line.split()[:1] in (["1"], ["2"], ["3"])]
    k_eta = [float(v) for r in rows for v in (r[1], r[3])]
    assert k_eta == pytest.approx([1 / 3, 1.0, 1 / 3, 2.0, 1 / 3, 3.0], rel=1e-5)


def test_damping_from_headerless_csv(tmp_path, capsys):
    t = np.arange(0, 150, 0.02)
    x = np.exp(-0.025 * t) * np.cos(math.sqrt(1 - 0.025**2) * t)
    path = tmp_path / "decay.csv"
    np.savetxt(path, np.column_stack([t, x]), delimiter=",")
    assert _invoke([str(path), "--kind", "damping", "--period", str(2 * math.pi),
                    "--mass", "2"]) == 0
    out = capsys.readouterr().out
    c = float(re.search(r"^c = (\S+)  \(m = 2\)$", out, re.M).group(1))
    assert c == pytest.approx(2 * 2 * 0.025, rel=1e-3)  # c = 2 m sigma


def test_bad_csv_is_one_line_error(tmp_path):
    path = tmp_path / "bad.csv"
    path.write_text("x,F\n1,2\n3,oops\n")
    with pytest.raises(IdentificationError, match=r"bad.csv: line 3: non-numeric"):
        _invoke([str(path), "--kind", "prandtl"])
    path.write_text("t,y\n1,2\n")
    with pytest.raises(IdentificationError, match=r"no column 'x' \(have t, y\)"):
        _invoke([str(path), "--kind", "damping"])
    with pytest.raises(IdentificationError, match="no such file"):
        _invoke([str(tmp_path / "missing.csv"), "--kind", "damping"])
