"""lagrange_gen.jit.speedups: one switch ($LAGRANGE_GEN_SPEEDUPS), the supported numba range, the
speedups' patches active only while a lagrange_gen function compiles, and each speedup falling
back to stock numba, with one warning line naming it, when the numba internals it touches are
absent or different."""

import copy
import gc
import os
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest
from numba.core import inline_closurecall
from numba.core.types.functions import BaseFunction

import lagrange_gen
from lg_test_support import ROOT
from lagrange_gen.jit import cache, callee, compile_gc, inline_copy, portable, speedups
from lagrange_gen.jit import typing_memo
from lagrange_gen.jit.cache import njit

_PACKAGE = Path(lagrange_gen.__file__).parent


@pytest.fixture(autouse=True)
def _fresh_checks():
    """Each test sees the checks and the once-per-process warnings anew."""
    def clear():
        speedups._warned.clear()
        speedups._unsupported.cache_clear()
        cache.closure_cache_unsupported.cache_clear()
    clear()
    yield
    clear()


def _fresh_function(filename=None, body="return x * 2.0 + y / 3.0"):
    """A new Python function (new, so numba compiles it in this test), optionally as if defined
    in the package file ``filename``."""
    namespace = {}
    code = compile(f"def fn(x, y):\n    {body}\n", filename or "<test>", "exec")
    exec(code, namespace)
    return namespace["fn"]


def _speedup_warnings(record, name):
    return [str(w.message) for w in record if f"speedup {name} off" in str(w.message)]


# -- the switch ------------------------------------------------------------------------------

@pytest.mark.parametrize("text, expected", [
    ("all", set(speedups.NAMES)), ("", set(speedups.NAMES)), ("none", set()),
    ("typing_memo,callee", {"typing_memo", "callee"}),
    ("-callee", set(speedups.NAMES) - {"callee"}),
    ("-callee,-compile_gc", set(speedups.NAMES) - {"callee", "compile_gc"}),
])
def test_the_switch(monkeypatch, text, expected):
    monkeypatch.setenv(speedups.ENV, text)
    assert speedups.selected() == expected


def test_an_unknown_name_warns_once(monkeypatch):
    monkeypatch.setenv(speedups.ENV, "typing_memo,no_such")
    with pytest.warns(RuntimeWarning, match="no_such"):
        assert speedups.selected() == {"typing_memo"}
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        speedups.selected()


def test_one_environment_variable():
    """The four variables of before are gone from the package; the switch is read in one
    module."""
    for old in ("NUMBA_TYPING_MEMO", "NUMBA_INLINE_COPY", "NUMBA_WRAPPERS", "COMPILE_GC"):
        for path in _PACKAGE.rglob("*.py"):
            assert f"LAGRANGE_GEN_{old}" not in path.read_text(), path
    readers = [p for p in _PACKAGE.rglob("*.py") if "LAGRANGE_GEN_SPEEDUPS\"" in p.read_text()]
    assert readers == [_PACKAGE / "jit" / "speedups.py"]


# -- the numba range -------------------------------------------------------------------------

def test_an_older_numba_is_refused_in_one_line():
    with pytest.raises(ImportError) as info:
        speedups.check_numba_version("0.58.1")
    message = str(info.value)
    assert "\n" not in message and "0.58.1" in message and "numba>=0.59,<0.69" in message


def test_a_newer_numba_warns_once_and_turns_the_speedups_off(monkeypatch):
    with pytest.warns(RuntimeWarning, match=r"numba 0\.70\.0 is newer .* speedups are off"):
        assert speedups.check_numba_version("0.70.0") is False
    monkeypatch.setattr(speedups, "numba_version", lambda: "0.70.0")
    assert speedups.selected() == frozenset()


def test_the_installed_numba_is_supported_and_pinned_alike():
    assert speedups.check_numba_version() is True
    text = (ROOT / "pyproject.toml").read_text()
    (a, b), (c, d) = speedups.SUPPORTED_NUMBA
    assert f'"numba>={a}.{b},<{c}.{d}"' in text


# -- scope -----------------------------------------------------------------------------------

_IMPORT_THEN_CHECK = """
import copy, gc, sys
from numba.core import inline_closurecall
from numba.core.types.functions import BaseFunction
original = BaseFunction.__dict__["get_call_type"]
threshold = gc.get_threshold()
import lagrange_gen, lagrange_gen.steppers
from lagrange_gen.run.loader import import_generated
mod = import_generated(sys.argv[1])
import numpy as np
from lagrange_gen.jit import typing_memo
kernel = mod.mass_matrix
assert BaseFunction.__dict__["get_call_type"] is original, "typing_memo left installed"
assert inline_closurecall.copy is copy, "inline_copy left installed"
assert gc.get_threshold() == threshold, "compile_gc left the thresholds"
print("OK", typing_memo.stats()["hits"] + typing_memo.stats()["misses"] > 0)
"""


def test_nothing_is_patched_after_importing_and_compiling(tmp_path):
    """Importing lagrange_gen and a generated module (whose import may compile a kernel), and
    compiling: numba's patched attributes are numba's own afterwards."""
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path))
    done = subprocess.run([sys.executable, "-c", _IMPORT_THEN_CHECK,
                           str(ROOT / "generated" / "cart_pendulum.py")],
                          capture_output=True, text=True, env=env, timeout=600)
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.startswith("OK")


def test_patches_are_active_only_inside_a_compile():
    original = BaseFunction.__dict__["get_call_type"]
    seen = {}

    @njit
    def probe(x):
        return x + 1.0

    compile_ = probe.compile.__wrapped__           # numba's own, inside the scope

    def spy(sig):
        seen["typing"] = BaseFunction.__dict__["get_call_type"] is not original
        seen["copy"] = isinstance(inline_closurecall.copy, inline_copy._BlockCopier)
        seen["gc"] = gc.get_threshold()[0] >= compile_gc.COMPILE_THRESHOLD
        return compile_(sig)

    probe.compile = _rescope(spy)
    assert probe(1.0) == 2.0
    assert seen == {"typing": True, "copy": True, "gc": True}
    assert BaseFunction.__dict__["get_call_type"] is original
    assert inline_closurecall.copy is copy


def _rescope(inner):
    def compile(sig):
        with speedups.compiling():
            return inner(sig)
    return compile


def test_speedups_none_patches_nothing(monkeypatch):
    monkeypatch.setenv(speedups.ENV, "none")
    original = BaseFunction.__dict__["get_call_type"]
    with speedups.compiling():
        assert BaseFunction.__dict__["get_call_type"] is original
        assert inline_closurecall.copy is copy


# -- fallbacks -------------------------------------------------------------------------------

def _compiles_alike(filename=None):
    fn = _fresh_function(filename)
    assert njit(fn)(3.0, 1.5) == fn(3.0, 1.5)


def test_typing_memo_falls_back_when_get_call_type_differs(monkeypatch):
    original = BaseFunction.__dict__["get_call_type"]

    def get_call_type(self, context, args, kws):          # not the statement the memo expects
        return original(self, context, args, kws)

    monkeypatch.setattr(BaseFunction, "get_call_type", get_call_type)
    with pytest.warns(RuntimeWarning) as record:
        with speedups.compiling():
            assert BaseFunction.__dict__["get_call_type"] is get_call_type
        _compiles_alike()
    assert len(_speedup_warnings(record, "typing_memo")) == 1


def test_inline_copy_falls_back_when_the_inliner_differs(monkeypatch):
    original = inline_closurecall.InlineWorker.inline_ir

    def inline_ir(self, *args, **kwargs):                  # no block-by-block deepcopy here
        return original(self, *args, **kwargs)

    monkeypatch.setattr(inline_closurecall.InlineWorker, "inline_ir", inline_ir)
    with pytest.warns(RuntimeWarning) as record:
        with speedups.compiling():
            assert inline_closurecall.copy is copy
        _compiles_alike()
    assert len(_speedup_warnings(record, "inline_copy")) == 1


def test_inline_copy_falls_back_when_numba_replaced_copy(monkeypatch):
    monkeypatch.setattr(inline_closurecall, "copy", object())
    with pytest.warns(RuntimeWarning) as record:
        _compiles_alike()
    assert len(_speedup_warnings(record, "inline_copy")) == 1


def test_callee_falls_back_when_numba_lacks_the_wrapper_options(monkeypatch):
    monkeypatch.setattr(callee, "NO_WRAPPERS", dict(no_cpython_wrapper=True,
                                                     no_such_wrapper_option=True))
    stepper_file = str(_PACKAGE / "steppers" / "core" / "_test_callee_fallback.py")
    fn = _fresh_function(stepper_file)
    with pytest.warns(RuntimeWarning) as record:
        dispatcher = njit(fn)
    assert type(dispatcher) is not callee.CalleeDispatcher
    assert dispatcher(3.0, 1.5) == fn(3.0, 1.5)
    assert len(_speedup_warnings(record, "callee")) == 1
    assert "no_such_wrapper_option" in _speedup_warnings(record, "callee")[0]


def test_callee_is_used_when_supported():
    stepper_file = str(_PACKAGE / "steppers" / "core" / "_test_callee_used.py")
    fn = _fresh_function(stepper_file)
    dispatcher = njit(fn)
    assert type(dispatcher) is callee.CalleeDispatcher
    assert dispatcher(3.0, 1.5) == fn(3.0, 1.5)


def test_a_failing_activation_falls_back(monkeypatch):
    def broken():
        raise AttributeError("moved")

    monkeypatch.setattr(compile_gc, "activate", broken)
    before = gc.get_threshold()
    with pytest.warns(RuntimeWarning) as record:
        _compiles_alike()
    assert gc.get_threshold() == before
    assert len(_speedup_warnings(record, "compile_gc")) == 1


def _linalg_function():
    from lagrange_gen.steppers.core import linalg
    return linalg.cholesky_inplace.py_func


def _spd():
    return np.array([[4.0, 1.0], [1.0, 3.0]])


def test_closure_cache_unsupported_compiles_package_functions_uncached(monkeypatch, tmp_path):
    import numba
    monkeypatch.setattr(numba.config, "CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(cache, "closure_cache_unsupported", lambda: "test: no stamp")
    with pytest.warns(RuntimeWarning) as record:
        dispatcher = njit(cache=True, _nrt=False)(_linalg_function())
    A = _spd()
    assert dispatcher(A) and np.allclose(np.tril(A) @ np.tril(A).T, _spd())
    assert type(dispatcher._cache).__name__ == "NullCache"
    assert len(_speedup_warnings(record, "closure_cache")) == 1


def test_a_failing_closure_stamp_is_a_miss_never_a_hit(monkeypatch, tmp_path):
    import numba
    monkeypatch.setattr(numba.config, "CACHE_DIR", str(tmp_path))
    first = njit(cache=True, _nrt=False)(_linalg_function())
    A = _spd()
    first(A)                                           # compiled and saved with its stamp
    assert list(tmp_path.rglob("*.nbi"))

    def broken(path):
        raise OSError("unreadable closure")

    monkeypatch.setattr(cache, "closure_stamp", broken)
    second = njit(cache=True, _nrt=False)(_linalg_function())
    with pytest.warns(RuntimeWarning) as record:
        assert second._cache.load_overload(first.signatures[0], second.targetctx) is None
    B = _spd()
    assert second(B) and np.array_equal(np.tril(A), np.tril(B))
    assert len(_speedup_warnings(record, "closure_cache")) == 1


def test_portable_falls_back_to_the_specialized_glue(monkeypatch):
    monkeypatch.setattr(portable, "unsupported", lambda: "test: no WrapperAddressProtocol")
    specialized = object()
    with pytest.warns(RuntimeWarning) as record:
        glue, what = portable.choose("portable", specialized, None, "midpoint", ())
    assert (glue, what) == (specialized, "specialized")
    assert len(_speedup_warnings(record, "portable")) == 1


def test_the_portable_glue_is_supported_here():
    assert portable.unsupported() is None
