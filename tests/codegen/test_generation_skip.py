"""Generating an unchanged model does not run its model file nor derive again (issue 40 item 6):
the generated module is current when the model file, every file it read or imported while it
ran, the options and the generator are what its derivation record says
(model_cache.generation_current, keys.changed_input). A change to any of them, or --force,
runs the file again. Each model file here appends to a counter file beside it when it runs."""

import os
import subprocess
import sys
import textwrap

import pytest

from lagrange_gen.cli.main import main
from lagrange_gen.codegen import generate_model

COUNTED = textwrap.dedent("""\
    import json
    from pathlib import Path
    from lagrange_gen import Model, coordinates, parameters
    here = Path(__file__)
    with open(here.with_suffix(".runs"), "a") as counter:
        counter.write("x")
    k0 = json.loads(here.with_name("stiffness.json").read_text())["k"]
    x = coordinates("x")
    k = parameters("k", defaults=(float(k0),))
    model = Model("counted_gen", coords=[x], T=x.d**2 / 2, V=k * x**2 / 2)
    """)


def _runs(path):
    counter = path.with_suffix(".runs")
    return len(counter.read_text()) if counter.exists() else 0


def _write(path, text):
    """Write ``text`` with an mtime a second later than before (coarse clocks)."""
    before = path.stat().st_mtime_ns if path.exists() else None
    path.write_text(text)
    if before is not None:
        os.utime(path, ns=(before + 10**9, before + 10**9))


@pytest.fixture
def counted(tmp_path):
    path = tmp_path / "counted_gen.py"
    path.write_text(COUNTED)
    _write(tmp_path / "stiffness.json", '{"k": 2.0}')
    return path


def _generate(path, *args):
    return main([str(path), "-o", str(path.parent / "gen"), *map(str, args)])


def test_an_unchanged_model_is_not_run_again(counted, capsys):
    assert _generate(counted, "--methods", "rk4") == 0
    assert _runs(counted) == 1
    capsys.readouterr()
    assert _generate(counted, "--methods", "rk4") == 0
    line = capsys.readouterr().out.strip()
    assert _runs(counted) == 1
    assert line.startswith(f"{counted.parent / 'gen' / 'counted_gen.py'} is current"), line
    result = generate_model(counted, counted.parent / "gen", methods=["rk4"])
    assert result.current and not result.written and _runs(counted) == 1


def test_a_changed_model_file_or_input_is_derived_again(counted, capsys):
    target = counted.parent / "gen" / "counted_gen.py"
    assert _generate(counted, "--methods", "rk4") == 0
    _write(counted, COUNTED.replace("float(k0)", "float(k0) + 1"))
    assert _generate(counted, "--methods", "rk4") == 0
    assert _runs(counted) == 2
    assert "DEFAULTS = (3.0,)" in target.read_text()
    _write(counted.parent / "stiffness.json", '{"k": 5.0}')
    assert _generate(counted, "--methods", "rk4") == 0
    assert _runs(counted) == 3
    assert "DEFAULTS = (6.0,)" in target.read_text()
    assert _generate(counted, "--methods", "rk4") == 0
    assert _runs(counted) == 3
    target.unlink()                                     # a deleted module is generated again
    assert _generate(counted, "--methods", "rk4") == 0
    assert _runs(counted) == 4 and "DEFAULTS = (6.0,)" in target.read_text()


def test_force_or_other_options_run_the_model_file(counted, capsys):
    assert _generate(counted, "--methods", "rk4") == 0
    assert _generate(counted, "--methods", "rk4", "--force") == 0
    assert _runs(counted) == 2
    capsys.readouterr()
    assert _generate(counted, "--methods", "rk4,midpoint") == 0      # another method set
    assert _runs(counted) == 3
    assert _generate(counted) == 0                                    # every method that applies
    assert _runs(counted) == 4
    assert _generate(counted) == 0
    assert _runs(counted) == 4
    assert _generate(counted, "--freeze", "k=2") == 0
    assert _runs(counted) == 5
    out = capsys.readouterr().out.splitlines()
    assert [line.split(":")[0].endswith("is current") for line in out] == [False, False, True, False]


def test_a_current_model_is_generated_without_importing_sympy(counted):
    assert _generate(counted, "--methods", "rk4") == 0
    code = ("import sys\nfrom lagrange_gen.cli.main import main\n"
            f"code = main([{str(counted)!r}, '-o', {str(counted.parent / 'gen')!r}, '--methods', 'rk4'])\n"
            "print(code, 'sympy' in sys.modules)\n")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert result.stdout.split()[-2:] == ["0", "False"], result.stdout + result.stderr
    assert "is current" in result.stdout and _runs(counted) == 1
