"""`lagrange-gen identify` on bad input: one line naming the file or option, a non-zero exit, no
traceback; a byte-order mark is not bad input (issue 11)."""

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from lagrange_gen.cli.main import main

LAGRANGE_GEN = Path(sys.executable).parent / "lagrange-gen"


def _decay_rows():
    t = np.arange(0, 150, 0.02)
    x = np.exp(-0.025 * t) * np.cos(math.sqrt(1 - 0.025**2) * t)
    return "".join(f"{a:.17g},{b:.17g}\n" for a, b in zip(t, x))


def _fails_in_one_line(capsys, argv, *needles):
    assert main(["identify", *argv]) != 0
    captured = capsys.readouterr()
    err = captured.err.strip()
    assert len(err.splitlines()) == 1 and "Traceback" not in err + captured.out, err
    for needle in needles:
        assert needle in err, err
    return err


def test_binary_file_is_one_line_error(tmp_path, capsys):
    path = tmp_path / "cycle.csv"
    path.write_bytes(bytes(range(256)) * 4)
    _fails_in_one_line(capsys, [str(path), "--kind", "prandtl"], str(path), "not a UTF-8 text file")


def test_latin1_csv_is_one_line_error_naming_the_line(tmp_path, capsys):
    path = tmp_path / "decay.csv"
    path.write_bytes("t,x\n0,1\n0.1,0.5\n# mesur\xe9\n".encode("latin-1"))
    _fails_in_one_line(capsys, [str(path), "--kind", "damping"], str(path), "line 4", "UTF-8")


def test_csv_with_byte_order_mark_reads_its_header(tmp_path, capsys):
    plain, marked = tmp_path / "plain.csv", tmp_path / "marked.csv"
    plain.write_text("t,x\n" + _decay_rows())
    marked.write_bytes(b"\xef\xbb\xbf" + plain.read_bytes())
    argv = ["--kind", "damping", "--period", str(2 * math.pi)]
    assert main(["identify", str(plain), *argv]) == 0
    expected = capsys.readouterr().out
    assert main(["identify", str(marked), *argv]) == 0
    out = capsys.readouterr().out
    assert out == expected and "c = " in out


@pytest.mark.parametrize("value", ["-1", "nan", "inf"])
def test_negative_or_non_finite_noise_is_refused(tmp_path, capsys, value):
    path = tmp_path / "cycle.csv"
    path.write_text("x,F\n" + "".join(f"{0.1 * i},{min(0.1 * i, 0.5)}\n" for i in range(40)))
    _fails_in_one_line(capsys, [str(path), "--kind", "prandtl", f"--noise={value}"],
                       f"--noise {value}", "must be a finite number >= 0")


def test_binary_file_through_the_installed_command(tmp_path):
    path = tmp_path / "image.csv"
    path.write_bytes(b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR\xff\xfe")
    run = subprocess.run([str(LAGRANGE_GEN), "identify", str(path), "--kind", "damping"],
                         capture_output=True, text=True, timeout=300)
    assert run.returncode != 0
    assert "Traceback" not in run.stderr and len(run.stderr.strip().splitlines()) == 1, run.stderr
    assert str(path) in run.stderr and "not a UTF-8 text file" in run.stderr


@pytest.mark.parametrize("value", [-1.0, float("nan"), float("inf")])
def test_python_api_refuses_a_meaningless_noise(value):
    from lagrange_gen.identify import IdentificationError
    from lagrange_gen.identify.prandtl import identify_prandtl
    x = np.linspace(0.0, 1.0, 50)
    with pytest.raises(IdentificationError, match="noise .*finite number >= 0"):
        identify_prandtl(x, 2.0 * x, 1, value)
