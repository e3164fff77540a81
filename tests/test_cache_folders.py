"""Cache folders that cannot be used: $LAGRANGE_GEN_PORTABLE_DIR naming a file or a read-only
directory gives one warning line and the per-user temporary directory (jit/portable.py), never a
traceback; the compile estimates and locks of jit/first_run.py follow the glue there;
$NUMBA_CACHE_DIR naming a file is numba's own business: it falls back to its other cache
locations and the run goes on."""

import errno
import os
import subprocess
import sys
import warnings
from pathlib import Path

import pytest

from lagrange_gen.errors import SimulationError
from lagrange_gen.jit import first_run, folders, portable
from lg_test_support import MODELS_DIR


@pytest.fixture
def fresh_glue(tmp_path, monkeypatch):
    """The portable glue written anew in this test: no remembered module or fallback; the
    per-user temporary directory under tmp_path."""
    portable._glue_module.cache_clear()
    monkeypatch.setattr(folders, "_FALLBACK_DIRS", {})
    monkeypatch.setattr(folders, "_temporary_dir", lambda: tmp_path / "per-user")
    for name in [m for m in sys.modules if m.startswith("lagrange_gen_portable_")]:
        monkeypatch.delitem(sys.modules, name)          # put back after the test
    yield tmp_path
    portable._glue_module.cache_clear()


def _read_only(monkeypatch, root):
    """Make every write under ``root`` fail as on a read-only file system (the tests run as
    root too, whom chmod does not stop)."""
    root = str(root)

    def guard(real):
        def call(path, *args, **kwargs):
            if str(path).startswith(root):
                raise OSError(errno.EROFS, os.strerror(errno.EROFS), str(path))
            return real(path, *args, **kwargs)
        return call

    monkeypatch.setattr(os, "mkdir", guard(os.mkdir))
    monkeypatch.setattr(os, "open", guard(os.open))


def _glue_with_warnings(method="explicit_euler"):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        module = portable._glue_module(method)
    return Path(module.__file__), [str(w.message) for w in caught]


def test_a_portable_dir_that_is_a_file_falls_back_with_one_warning(fresh_glue, monkeypatch):
    afile = fresh_glue / "afile"
    afile.write_text("not a directory")
    monkeypatch.setenv(portable.DIR_ENV, str(afile))
    path, messages = _glue_with_warnings()
    assert path.is_file() and path.parent.parent == fresh_glue / "per-user"
    assert len(messages) == 1 and "\n" not in messages[0]
    assert f"{portable.DIR_ENV}={afile}" in messages[0] and str(fresh_glue / "per-user") in messages[0]
    # the estimates and locks of the background compile follow the glue, without a second line
    assert portable.portable_dir() == fresh_glue / "per-user"
    assert first_run.lock_path("explicit_euler").parent == path.parent
    first_run.record_compile_seconds("explicit_euler", 3.0)
    assert first_run.expected_compile_seconds("explicit_euler") == 3.0
    assert afile.read_text() == "not a directory"
    assert _glue_with_warnings("verlet")[1] == []


def test_a_read_only_portable_dir_falls_back_with_one_warning(fresh_glue, monkeypatch):
    read_only = fresh_glue / "read-only"
    read_only.mkdir()
    monkeypatch.setenv(portable.DIR_ENV, str(read_only))
    _read_only(monkeypatch, read_only)
    path, messages = _glue_with_warnings()
    assert path.parent.parent == fresh_glue / "per-user"
    assert len(messages) == 1 and "Read-only file system" in messages[0]
    assert list(read_only.iterdir()) == []


def test_a_read_only_dir_holding_the_glue_is_only_read(fresh_glue, monkeypatch):
    """A shared install: the glue of this library version is there already; nothing is written
    and nothing is said."""
    shared = fresh_glue / "shared"
    monkeypatch.setenv(portable.DIR_ENV, str(shared))
    written, _ = _glue_with_warnings()
    portable._glue_module.cache_clear()
    _read_only(monkeypatch, shared)
    path, messages = _glue_with_warnings()
    assert path == written and messages == []


def test_no_writable_place_at_all_is_one_line(fresh_glue, monkeypatch):
    afile = fresh_glue / "afile"
    afile.write_text("")
    monkeypatch.setenv(portable.DIR_ENV, str(afile))
    _read_only(monkeypatch, fresh_glue / "per-user")
    with pytest.raises(SimulationError) as info:
        _glue_with_warnings()
    message = str(info.value)
    assert "\n" not in message and str(afile) in message and portable.DIR_ENV in message
    assert str(fresh_glue / "per-user") in message


def test_the_temporary_dir_is_per_user(monkeypatch):
    if not hasattr(os, "getuid"):
        pytest.skip("no user ids here")
    assert folders._temporary_dir().name == f"lagrange_gen_portable-{os.getuid()}"


@pytest.mark.parametrize("kind", ["portable", "numba"])
def test_a_cache_variable_naming_a_file_runs_without_a_traceback(tmp_path, kind):
    """The whole way, in a fresh process: simulate with the variable naming a file."""
    afile = tmp_path / "afile"
    afile.write_text("")
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "numba"),
               LAGRANGE_GEN_PORTABLE_DIR=str(tmp_path / "portable"),
               LAGRANGE_GEN_BACKGROUND_COMPILE="0", LAGRANGE_GEN_INTERPRETED="0", TMPDIR=str(tmp_path))
    env["NUMBA_CACHE_DIR" if kind == "numba" else "LAGRANGE_GEN_PORTABLE_DIR"] = str(afile)
    child = ("import sys\n"
             "from lagrange_gen.run.simulate import simulate\n"
             "traj = simulate(sys.argv[1], 'explicit_euler', [0.1], None, t_end=0.01, h=1e-3, "
             "jit='portable', out_dir=sys.argv[2])\n"
             "print(traj.jit, traj.q[-1][0])\n")
    done = subprocess.run([sys.executable, "-c", child, str(MODELS_DIR / "damped_oscillator.py"),
                           str(tmp_path / "gen")], env=env, capture_output=True, text=True,
                          timeout=600)
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.split()[0] == "portable"
    assert "Traceback" not in done.stderr
    warned = [line for line in done.stderr.splitlines() if "cannot be written" in line]
    assert len(warned) == (1 if kind == "portable" else 0)
    assert afile.read_text() == ""
