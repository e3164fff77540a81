"""The numba speedups: which are on, the supported numba range, and the scope they patch in.

One switch, $LAGRANGE_GEN_SPEEDUPS, read here only (``selected``):

- ``all`` (default) or empty: every speedup of NAMES;
- ``none``: none of them: numba compiles as shipped;
- ``name,name``: those; ``-name,...`` (only removals): all but those.

NAMES: ``typing_memo`` (typing_memo.py), ``inline_copy`` (inline_copy.py), ``callee``
(callee.py), ``compile_gc`` (compile_gc.py). ``lagrange-gen bench compile`` measures each on
and off, so that one numba has caught up with can be retired.

Each speedup checks the numba internals it touches (attributes, and the source statements it
stands for) on first use; when they are absent or different it is off for the process and one
warning line names it (``fallback``): numba then compiles as shipped.

Scope: typing_memo, inline_copy and compile_gc change numba (or the interpreter) only while a
function decorated by lagrange_gen.jit.njit compiles (``compiling``, around that dispatcher's
``compile``, which numba's cache loads go through too): importing lagrange_gen changes nothing
in numba, and a compile of someone else's function outside ours runs stock numba.

Supported numba: SUPPORTED_NUMBA (the versions this package has run on: 0.59.1, 0.61.2,
0.68.1). An older numba is refused at import with one line (check_numba_version); a newer one
runs with every speedup off, with one warning line: the speedups reach into internals a new
release may have changed in ways the checks do not see.
"""

from __future__ import annotations

import functools
import os
import re
import threading
import warnings
from contextlib import contextmanager

#: Environment variable selecting the speedups (module docstring).
ENV = "LAGRANGE_GEN_SPEEDUPS"

#: The speedups $LAGRANGE_GEN_SPEEDUPS names.
NAMES = ("typing_memo", "inline_copy", "callee", "compile_gc")

#: numba versions supported: (lowest, first unsupported), as in pyproject.toml. Run: 0.59.1,
#: 0.61.2, 0.68.1.
SUPPORTED_NUMBA = ((0, 59), (0, 69))

_warned: set = set()


def _warn_once(key, message):
    if key not in _warned:
        _warned.add(key)
        warnings.warn(message, RuntimeWarning, stacklevel=3)


@functools.lru_cache(maxsize=None)
def numba_version() -> str | None:
    """The installed numba's version string (from its metadata: numba is not imported), or
    None when it is not installed."""
    from importlib import metadata
    try:
        return metadata.version("numba")
    except metadata.PackageNotFoundError:
        return None


def _version_tuple(text):
    match = re.match(r"(\d+)\.(\d+)", text)
    return (int(match[1]), int(match[2])) if match else (0, 0)


def _range_text():
    (a, b), (c, d) = SUPPORTED_NUMBA
    return f"numba>={a}.{b},<{c}.{d}"


def check_numba_version(version=None) -> bool:
    """ImportError (one line) when numba is older than SUPPORTED_NUMBA allows; one warning, and
    False, when it is newer (every speedup is then off); True inside the range (or numba not
    installed: its import will say so)."""
    version = numba_version() if version is None else version
    if version is None:
        return True
    found = _version_tuple(version)
    low, high = SUPPORTED_NUMBA
    if found < low:
        raise ImportError(f"lagrange-gen needs {_range_text()}; numba {version} is installed")
    if found >= high:
        _warn_once("version", f"lagrange-gen: numba {version} is newer than the supported "
                              f"{_range_text()}; its compile speedups are off")
        return False
    return True


def selected() -> frozenset:
    """The speedups $LAGRANGE_GEN_SPEEDUPS selects (module docstring); unknown names give one
    warning each and are ignored. None when numba is newer than supported."""
    if not check_numba_version():
        return frozenset()
    text = os.environ.get(ENV, "all").strip().lower()
    if text in ("", "all"):
        return frozenset(NAMES)
    if text == "none":
        return frozenset()
    names = [n.strip() for n in text.split(",") if n.strip()]
    for name in names:
        if name.lstrip("-") not in NAMES:
            _warn_once(("name", name), f"lagrange-gen: ${ENV} names an unknown speedup "
                                       f"{name!r}; known: {', '.join(NAMES)}")
    if names and all(n.startswith("-") for n in names):
        return frozenset(NAMES) - {n[1:] for n in names}
    return frozenset(n for n in names if n in NAMES)


def fallback(name, reason):
    """Warn once per process that speedup ``name`` is off because numba's internals differ."""
    _warn_once(("fallback", name), f"lagrange-gen: speedup {name} off ({reason}); numba "
                                   f"compiles as shipped")


def enabled(name) -> bool:
    """Whether speedup ``name`` is selected and the numba internals it touches are there (a
    missing one warns once, ``fallback``)."""
    if name not in selected():
        return False
    reason = _unsupported(name)
    if reason is not None:
        fallback(name, reason)
        return False
    return True


@functools.lru_cache(maxsize=None)
def _unsupported(name):
    """None when the numba internals speedup ``name`` touches are as it expects, else why not
    (checked once per process)."""
    import importlib
    try:
        return importlib.import_module(f"{__package__}.{name}").unsupported()
    except Exception as exc:      # a check that fails is a no
        return f"{type(exc).__name__}: {exc}".splitlines()[0]


def _activators():
    from . import compile_gc, inline_copy, typing_memo
    return {"typing_memo": typing_memo.activate, "inline_copy": inline_copy.activate,
            "compile_gc": compile_gc.activate}


_depth = 0
_restore: list = []
_scope_lock = threading.RLock()


@contextmanager
def compiling():
    """Context of a compile of a lagrange_gen function: the patching speedups are active from
    the outermost entry to its exit (nested compiles share it), failed compiles included. Holds
    numba's compiler lock, so no other thread compiles meanwhile."""
    from numba.core.compiler_lock import global_compiler_lock
    global _depth
    with global_compiler_lock, _scope_lock:
        _depth += 1
        try:
            if _depth == 1:
                for name, activate in _activators().items():
                    if enabled(name):
                        try:
                            _restore.append(activate())
                        except Exception as exc:      # internals moved: stock numba
                            fallback(name, f"{type(exc).__name__}: {exc}".splitlines()[0])
            yield
        finally:
            _depth -= 1
            if _depth == 0:
                while _restore:
                    _restore.pop()()


def scope(dispatcher):
    """Make ``dispatcher`` (a numba Dispatcher) compile inside ``compiling``: numba compiles
    through ``self.compile`` both for a call from Python (_compile_for_args) and for the typing
    of a call from jitted code (get_call_template), cache loads included."""
    compile_ = getattr(dispatcher, "compile", None)
    if compile_ is None or not hasattr(dispatcher, "overloads"):
        return dispatcher          # NUMBA_DISABLE_JIT: the plain function

    def compile(sig):
        with compiling():
            return compile_(sig)

    compile.__wrapped__ = compile_
    dispatcher.compile = compile
    return dispatcher
