"""A generated module is current only when its whole text is what the generator would write now.

Issue 10 item 4 (hand edits, data files and helper modules a model reads, two model files with
the same model name) and issue 11 (options of a generated module kept by load/simulate, hints
that quote paths and keep -o). Run as a user would: lagrange_gen.cli.main, the CLI in a
subprocess for what must not be cached in this process, and the public API.
"""

import shlex
import shutil
import subprocess
import sys
import textwrap

import pytest

from lg_test_support import MODELS_DIR, ROOT
from lagrange_gen.cli.main import main
from lagrange_gen.errors import GenerationError, StaleModuleError

CLI = str(ROOT / ".venv" / "bin" / "lagrange-gen")
ONE_METHOD = ["--methods", "midpoint"]


def run_cli(*args, cwd=None):
    return subprocess.run([CLI, *map(str, args)], capture_output=True, text=True, cwd=cwd, timeout=600)


def spring_file(path, stiffness_expr, name="spring", prelude=""):
    """A one-coordinate model file whose stiffness is the Python expression stiffness_expr."""
    path.write_text(textwrap.dedent(prelude) + textwrap.dedent(f"""
        from lagrange_gen import Model, coordinates, parameters
        x = coordinates("x")
        m = parameters("m", defaults=(1.0,))
        model = Model({name!r}, coords=[x], T=m * x.d**2 / 2, V={stiffness_expr} * x**2 / 2)
    """))
    return path


def test_hand_edited_kernel_fails_import_and_check(tmp_path, capsys):
    model = shutil.copy(MODELS_DIR / "damped_oscillator.py", tmp_path / "damped_oscillator.py")
    out = tmp_path / "out"
    assert main([str(model), "-o", str(out), *ONE_METHOD]) == 0
    target = out / "damped_oscillator.py"
    text = target.read_text()
    body_line = next(line for line in text.splitlines() if line.startswith("    out[0] = "))
    target.write_text(text.replace(body_line, body_line + " * 2.0", 1))   # KEY line untouched
    from lagrange_gen.run.loader import import_generated
    with pytest.raises(StaleModuleError, match=r"damped_oscillator\.py.*edited.*lagrange-gen .*damped_oscillator\.py"):
        import_generated(target)
    capsys.readouterr()
    assert main(["--check", str(model), "-o", str(out), *ONE_METHOD]) == 1
    out_text = capsys.readouterr().out
    assert str(target) in out_text and "stale" in out_text and "edited" in out_text, out_text


def test_check_sees_a_changed_data_file(tmp_path, capsys):
    data = tmp_path / "stiffness.txt"
    data.write_text("2.0\n")
    model = spring_file(tmp_path / "spring.py", "k_value", prelude="""
        from pathlib import Path
        k_value = float((Path(__file__).parent / "stiffness.txt").read_text())
    """)
    out = tmp_path / "out"
    assert main([str(model), "-o", str(out), *ONE_METHOD]) == 0
    before = (out / "spring.py").read_bytes()
    assert main(["--check", str(model), "-o", str(out), *ONE_METHOD]) == 0
    data.write_text("2.0 \n\n")                       # same equations: still current
    assert main(["--check", str(model), "-o", str(out), *ONE_METHOD]) == 0
    capsys.readouterr()
    data.write_text("3.0\n")
    assert main(["--check", str(model), "-o", str(out), *ONE_METHOD]) == 1
    line = capsys.readouterr().out.strip()
    assert str(out / "spring.py") in line and "stale" in line, line
    assert (out / "spring.py").read_bytes() == before          # --check writes nothing


def test_check_sees_a_changed_helper_module(tmp_path):
    helper = tmp_path / "spring_helper.py"
    helper.write_text("STIFFNESS = 2.0\n")
    model = spring_file(tmp_path / "spring.py", "spring_helper.STIFFNESS", prelude="""
        import sys
        from pathlib import Path
        sys.path.insert(0, str(Path(__file__).parent))
        import spring_helper
    """)
    out = tmp_path / "out"
    assert run_cli(model, "-o", out, *ONE_METHOD).returncode == 0
    assert run_cli("--check", model, "-o", out, *ONE_METHOD).returncode == 0
    helper.write_text("STIFFNESS = 5.0\n")
    result = run_cli("--check", model, "-o", out, *ONE_METHOD)
    assert result.returncode == 1, result
    assert str(out / "spring.py") in result.stdout and "stale" in result.stdout, result.stdout
    assert "Traceback" not in result.stderr


def test_same_model_name_from_two_files_is_refused(tmp_path, capsys):
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    first = spring_file(tmp_path / "a" / "spring.py", "2.0")
    second = spring_file(tmp_path / "b" / "spring.py", "7.0")
    out = tmp_path / "out"
    assert main([str(first), "-o", str(out), *ONE_METHOD]) == 0
    before = (out / "spring.py").read_bytes()
    capsys.readouterr()
    assert main([str(second), "-o", str(out), *ONE_METHOD]) != 0
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "--force" in err, err
    assert str(first.resolve()) in err or str(first) in err, err
    assert str(second) in err, err
    assert (out / "spring.py").read_bytes() == before
    assert main([str(second), "-o", str(out), *ONE_METHOD, "--force"]) == 0
    assert "7.0" in (out / "spring.py").read_text()


@pytest.fixture
def frozen_cart(tmp_path):
    """cart_pendulum generated with --freeze g=1.62 (midpoint only) into tmp_path/out."""
    model = shutil.copy(MODELS_DIR / "cart_pendulum.py", tmp_path / "cart_pendulum.py")
    out = tmp_path / "out"
    assert main([str(model), "-o", str(out), "--freeze", "g=1.62", *ONE_METHOD]) == 0
    return model, out, out / "cart_pendulum.py"


def test_load_keeps_the_freeze_of_a_current_module(frozen_cart):
    import lagrange_gen as lg
    model, out, target = frozen_cart
    before = target.read_bytes()
    mod = lg.load(model, out_dir=out)
    assert mod.FROZEN == {"g": 1.62} and "g" not in mod.PARAMS
    assert target.read_bytes() == before


def test_load_asked_for_another_freeze_says_what_differs(frozen_cart):
    import lagrange_gen as lg
    model, out, target = frozen_cart
    before = target.read_bytes()
    with pytest.raises(GenerationError) as info:
        lg.load(model, out_dir=out, freeze={})
    message = str(info.value)
    assert "\n" not in message and "g=1.62" in message and str(target) in message, message
    assert target.read_bytes() == before


def test_load_adds_a_missing_method_keeping_the_freeze(frozen_cart):
    import lagrange_gen as lg
    model, out, target = frozen_cart
    mod = lg.load(model, out_dir=out, methods=["rk4"])
    assert mod.FROZEN == {"g": 1.62}
    assert set(mod.METHODS) == {"midpoint", "rk4"}


def test_load_regenerates_a_stale_module_with_its_freeze(frozen_cart):
    import lagrange_gen as lg
    model, out, target = frozen_cart
    model.write_text(model.read_text().replace("10.0, 9.81", "12.0, 9.81"))
    mod = lg.load(model, out_dir=out)
    assert mod.FROZEN == {"g": 1.62} and mod.DEFAULTS[mod.PARAMS.index("k")] == 12.0


def test_simulate_cli_uses_the_frozen_module(frozen_cart):
    model, out, target = frozen_cart
    before = target.read_bytes()
    result = run_cli("simulate", model, "--gen-dir", out, "--method", "midpoint", "--h", "0.01",
                     "--t-end", "0.05", "--q0", "0", "0.3")
    assert result.returncode == 0, result.stderr
    assert target.read_bytes() == before


def test_hints_quote_paths_and_keep_the_output_directory(tmp_path, capsys):
    where = tmp_path / "my models"
    where.mkdir()
    model = shutil.copy(MODELS_DIR / "damped_oscillator.py", where / "damped oscillator.py")
    out = tmp_path / "gen out"
    assert main([str(model), "-o", str(out), *ONE_METHOD]) == 0
    capsys.readouterr()
    assert main(["--check", str(model), "-o", str(out), "--methods", "midpoint,rk4"]) == 1
    line = capsys.readouterr().out.strip()
    hint = shlex.split(line.rsplit("; run ", 1)[1])
    assert hint[0] == "lagrange-gen" and str(model) in hint and str(out) in hint, line
    assert main(hint[1:]) == 0                      # following the hint makes the check pass
    assert main(["--check", str(model), "-o", str(out), "--methods", "midpoint,rk4"]) == 0


def test_regeneration_command_of_a_module(tmp_path):
    """keys.regeneration_command_for: the command that regenerates a generated module with more
    methods, with -o and quoted paths (what the simulate hint prints)."""
    from lagrange_gen.codegen.keys import regeneration_command_for
    from lagrange_gen.run.loader import import_generated
    model = shutil.copy(MODELS_DIR / "damped_oscillator.py", tmp_path / "damped oscillator.py")
    out = tmp_path / "gen out"
    assert main([str(model), "-o", str(out), "--freeze", "c=2", *ONE_METHOD]) == 0
    mod = import_generated(out / "damped_oscillator.py")
    command = regeneration_command_for(mod, methods=["rk4"])
    args = shlex.split(command)
    assert args[0] == "lagrange-gen", command
    assert main(args[1:]) == 0
    text = (out / "damped_oscillator.py").read_text()
    assert "METHODS = ('midpoint', 'rk4')" in text and "FROZEN = {'c': 2.0}" in text
    assert sorted(p.name for p in out.iterdir() if p.suffix == ".py") == ["damped_oscillator.py"]
