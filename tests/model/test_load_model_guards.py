"""load_model runs the user's file: whatever that file does (exit, interrupt-like exceptions,
chdir, several Models) ends in one ModelError line naming the file, or in a generated module
where the message says (issue 11 rows)."""

import os
import re
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from lagrange_gen import ModelError, load_model

HEADER = "from lagrange_gen import Model, coordinates, parameters\n"
SPRING = HEADER + textwrap.dedent("""\
    x = coordinates("x")
    k = parameters("k", defaults=(2.0,))
    {name} = Model("{model}", coords=[x], T=x.d**2 / 2, V=k * x**2 / 2)
""")
LAGRANGE_GEN = Path(sys.executable).parent / "lagrange-gen"


def _error(path):
    with pytest.raises(ModelError) as info:
        load_model(path)
    message = str(info.value)
    assert "\n" not in message, message
    return message


@pytest.mark.parametrize("statement, what", [
    ("import sys; sys.exit(0)", "SystemExit"),
    ("import sys; sys.exit('bye')", "SystemExit"),
    ("raise GeneratorExit()", "GeneratorExit"),
    ("class Stop(BaseException): pass\nraise Stop('halt')", "Stop"),
])
def test_base_exception_while_loading_is_a_model_error_with_file_and_line(tmp_path, statement, what):
    path = tmp_path / "quits.py"
    lines = SPRING.format(name="model", model="quits") + statement + "\n"
    path.write_text(lines)
    line = len(lines.splitlines())                 # the statement's (last) line raises
    message = _error(path)
    assert message.startswith(f"{path}:{line}: "), message
    assert what in message, message


def test_sys_exit_in_first_file_stops_the_cli_with_nonzero_exit(tmp_path):
    """`lagrange-gen a.py b.py` where a.py calls sys.exit(0): non-zero exit, one line, no
    traceback (never a silent exit 0 with nothing generated)."""
    a, b = tmp_path / "a.py", tmp_path / "b.py"
    a.write_text(SPRING.format(name="model", model="a") + "import sys\nsys.exit(0)\n")
    b.write_text(SPRING.format(name="model", model="b"))
    run = subprocess.run([str(LAGRANGE_GEN), str(a), str(b), "-o", str(tmp_path / "out")],
                         capture_output=True, text=True, timeout=300)
    assert run.returncode != 0, run
    assert "Traceback" not in run.stderr, run.stderr
    assert re.search(rf"{re.escape(str(a))}:6: .*SystemExit", run.stderr), run.stderr


def test_keyboard_interrupt_while_loading_stays_an_interrupt(tmp_path, monkeypatch, capsys):
    """Ctrl-C (or a file raising KeyboardInterrupt, which looks the same) is not turned into a
    model error that a loop over files would skip: the CLI reports "interrupted", exit 130, and
    the directory the file changed to is left again."""
    from lagrange_gen.cli.main import main
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    path = tmp_path / "interrupted.py"
    path.write_text(f"import os\nos.chdir({str(elsewhere)!r})\nraise KeyboardInterrupt\n")
    monkeypatch.chdir(tmp_path)
    assert main([str(path), "-o", str(tmp_path / "out")]) == 130
    assert capsys.readouterr().err.strip() == "lagrange-gen: interrupted"
    assert Path.cwd() == tmp_path


def test_chdir_in_model_file_does_not_move_the_output(tmp_path, monkeypatch):
    """The file changes directory while loading; the module is written where the CLI says,
    relative to the directory the user ran it from, and that directory is restored."""
    work, elsewhere = tmp_path / "work", tmp_path / "elsewhere"
    work.mkdir(), elsewhere.mkdir()
    model = work / "wander.py"
    model.write_text(f"import os\nos.chdir({str(elsewhere)!r})\n" + SPRING.format(name="model", model="wander"))
    run = subprocess.run([str(LAGRANGE_GEN), "wander.py", "-o", "gen"], cwd=work,
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    assert run.stdout.startswith("gen/wander.py: written"), run.stdout
    assert (work / "gen" / "wander.py").is_file()
    assert not (elsewhere / "gen").exists()
    monkeypatch.chdir(work)
    load_model("wander.py")
    assert Path.cwd() == work


def test_chdir_then_raise_names_the_file_and_line(tmp_path, monkeypatch):
    work, elsewhere = tmp_path / "work", tmp_path / "elsewhere"
    work.mkdir(), elsewhere.mkdir()
    (work / "bad.py").write_text(f"import os\nos.chdir({str(elsewhere)!r})\nraise ValueError('late')\n")
    monkeypatch.chdir(work)
    message = _error("bad.py")
    assert message.startswith("bad.py:3: raised ValueError: late"), message
    assert Path.cwd() == work


def test_two_models_none_named_model_are_listed(tmp_path):
    path = tmp_path / "pair.py"
    path.write_text(SPRING.format(name="first", model="a")
                    + "second = Model('b', coords=[x], T=x.d**2, V=k * x**4)\n")
    message = _error(path)
    assert message == (f"{path}: defines 2 Models (first, second) and none is named `model`: "
                       "assign the one to generate to `model`"), message


def test_one_model_under_another_name_is_still_taken(tmp_path):
    path = tmp_path / "single.py"
    path.write_text(SPRING.format(name="spring", model="single"))
    assert load_model(path).name == "single"


def test_no_model_at_all_says_so(tmp_path):
    path = tmp_path / "empty.py"
    path.write_text("x = 1\n")
    assert "defines no Model" in _error(path)
    assert os.path.exists(path)
