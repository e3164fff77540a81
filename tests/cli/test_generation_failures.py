"""Generation and loading fail one line at a time and lose nothing (issue 11 rows).

File modes, temp files of killed writers, progress of slow generations, one broken model among
several, importing with importlib by hand, a corrupt numba cache. Run as a user would: the CLI
in a subprocess or lagrange_gen.cli.main.
"""

import os
import shutil
import stat
import subprocess
import sys
import textwrap

import pytest
from pathlib import Path

from lg_test_support import MODELS_DIR, ROOT
from lagrange_gen.cli.main import main

CLI = str(ROOT / ".venv" / "bin" / "lagrange-gen")
PYTHON = str(ROOT / ".venv" / "bin" / "python")
ONE_METHOD = ["--methods", "midpoint"]
GOOD = textwrap.dedent("""
    from lagrange_gen import Model, coordinates, parameters
    x = coordinates("x")
    m = parameters("m", defaults=(1.0,))
    model = Model(NAME, coords=[x], T=m * x.d**2 / 2, V=2 * x**2)
""")


def run(*args, cwd=None):
    return subprocess.run([*map(str, args)], capture_output=True, text=True, cwd=cwd, timeout=600)


def dead_pid():
    """The pid of a process that has exited (and been reaped)."""
    child = subprocess.Popen([sys.executable, "-c", "pass"])
    child.wait()
    return child.pid


@pytest.fixture
def oscillator(tmp_path):
    model = shutil.copy(MODELS_DIR / "damped_oscillator.py", tmp_path / "damped_oscillator.py")
    return model, tmp_path / "out"


def test_generated_file_mode_follows_umask_and_is_kept(oscillator):
    model, out = oscillator
    old = os.umask(0o022)
    try:
        assert main([str(model), "-o", str(out), *ONE_METHOD]) == 0
        target = out / "damped_oscillator.py"
        assert stat.S_IMODE(target.stat().st_mode) == 0o644
        target.chmod(0o640)
        assert main([str(model), "-o", str(out), "--methods", "rk4"]) == 0    # rewritten
        assert "METHODS = ('rk4',)" in target.read_text()
        assert stat.S_IMODE(target.stat().st_mode) == 0o640
    finally:
        os.umask(old)


def test_temp_file_of_a_dead_writer_is_removed(oscillator):
    model, out = oscillator
    assert main([str(model), "-o", str(out), *ONE_METHOD]) == 0
    stale = out / f".damped_oscillator.py.{dead_pid()}.tmp"
    stale.write_text("half a module")
    alive = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
    try:
        busy = out / f".damped_oscillator.py.{alive.pid}.tmp"
        busy.write_text("being written")
        other = out / f".other.py.{dead_pid()}.tmp"       # another target: not ours to judge now
        other.write_text("x")
        assert main([str(model), "-o", str(out), "--methods", "rk4"]) == 0
        assert not stale.exists()
        assert busy.exists() and other.exists()
    finally:
        alive.kill()
        alive.wait()
    names = sorted(p.name for p in out.iterdir())
    assert ".damped_oscillator.py" not in " ".join(n for n in names if n != busy.name), names


def test_progress_lines_for_slow_stages_only(oscillator, capsys, monkeypatch):
    from lagrange_gen.codegen import generate
    model, out = oscillator
    assert main([str(model), "-o", str(out), *ONE_METHOD]) == 0
    assert capsys.readouterr().err == ""                       # a small model is quiet
    monkeypatch.setattr(generate, "PROGRESS_AFTER", 0.0)      # every stage counts as slow
    assert main([str(model), "-o", str(out), "--methods", "rk4"]) == 0
    err = capsys.readouterr().err
    for stage in ("load model", "derive", "emit", "write"):
        assert any(stage in line and "done in" in line and str(model) in line
                   for line in err.splitlines()), err


def test_one_broken_model_does_not_stop_the_others(tmp_path):
    (tmp_path / "broken.py").write_text("model = (\n")
    (tmp_path / "exits.py").write_text("import sys\nsys.exit(0)\n")
    (tmp_path / "good.py").write_text("NAME = 'good'\n" + GOOD)
    files = [tmp_path / "broken.py", tmp_path / "exits.py", tmp_path / "good.py"]
    out = tmp_path / "out"
    result = run(CLI, *files, "-o", out, *ONE_METHOD)
    assert result.returncode != 0
    assert "Traceback" not in result.stderr
    err = result.stderr.strip().splitlines()
    assert len(err) == 3 and "broken.py" in err[0] and "exits.py" in err[1], result.stderr
    assert err[2] == f"lagrange-gen: 2 of 3 model files failed: {files[0]}, {files[1]}"
    assert (out / "good.py").is_file()
    check = run(CLI, "--check", *files, "-o", out, *ONE_METHOD)
    assert check.returncode != 0 and "Traceback" not in check.stderr
    assert "broken.py" in check.stderr and "exits.py" in check.stderr, check.stderr
    assert f"{out / 'good.py'}: current" in check.stdout, check.stdout


IMPORT_BY_HAND = """
import importlib.util, sys
spec = importlib.util.spec_from_file_location("my_oscillator", sys.argv[1])
mod = importlib.util.module_from_spec(spec)
spec.loader.exec_module(mod)
import lagrange_gen as lg
traj = lg.simulate(mod, method="midpoint", q0=[1.0], v0=[0.0], t_end=0.1, h=0.01)
print(traj.q[-1][0])
"""


def test_import_with_spec_from_file_location(oscillator):
    model, out = oscillator
    assert main([str(model), "-o", str(out), *ONE_METHOD]) == 0
    result = run(PYTHON, "-c", IMPORT_BY_HAND, out / "damped_oscillator.py")
    assert result.returncode == 0, result.stderr
    import math
    assert float(result.stdout) == pytest.approx(math.cos(0.1), abs=1e-4)


def test_corrupt_numba_cache_is_a_miss(oscillator, monkeypatch):
    model, out = oscillator
    portable = out.parent / "portable"        # where the library writes the module's glue
    monkeypatch.setenv("LAGRANGE_GEN_PORTABLE_DIR", str(portable))
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)   # caches beside the sources
    assert main([str(model), "-o", str(out), *ONE_METHOD]) == 0
    simulate = [CLI, "simulate", out / "damped_oscillator.py", "--method", "midpoint",
                "--h", "0.01", "--t-end", "0.1", "--q0", "1", "--v0", "0", "--jit", "specialized"]
    first = run(*simulate)
    assert first.returncode == 0, first.stderr
    index = next(portable.rglob("*damped_oscillator_*.run_midpoint-*.nbi"))
    index.write_bytes(b"garbage, not a pickle")
    data = next((out / "__pycache__").glob("damped_oscillator.energy-*.nbc"))
    data.write_bytes(data.read_bytes()[: data.stat().st_size // 2])
    second = run(*simulate)
    assert second.returncode == 0, second.stderr
    assert "Traceback" not in second.stderr
    # one warning per corrupt file, the glue's index and the kernel's data (the second comes
    # while the glue compiles, inside the first-use notice "lagrange-gen: compiling ... done")
    import re
    warned = re.findall(r"lagrange-gen: warning: numba cache of (\S+) unreadable", second.stderr)
    assert sorted(Path(w).name for w in warned) == sorted(
        [index.name.split(".")[0] + ".py", "damped_oscillator.py"]), second.stderr
    final = [line for line in first.stdout.splitlines() if line.startswith("final q")]
    assert final and final[0] in second.stdout.splitlines(), (first.stdout, second.stdout)
    third = run(*simulate)                                   # rebuilt: no warning any more
    assert third.returncode == 0 and third.stderr == "", third.stderr


def test_import_after_regeneration_in_the_same_process_gives_the_new_module(tmp_path):
    """import_generated caches modules by path: after the file is regenerated (here with another
    method), the same process must get the new text, not the module object imported before."""
    from lagrange_gen.codegen import generate_model
    from lagrange_gen.run.loader import import_generated
    model = ROOT / "models" / "damped_oscillator.py"
    first = import_generated(generate_model(model, tmp_path, methods=["rk4"]).path)
    assert not hasattr(first, "run_verlet")
    second = import_generated(generate_model(model, tmp_path, methods=["rk4", "verlet"]).path)
    assert hasattr(second, "run_verlet") and second.KEY != first.KEY
