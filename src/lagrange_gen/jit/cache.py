"""``numba.njit`` with an on-disk cache that is never stale and never fatal.

Every jitted function of the package and of the generated modules is decorated by ``njit``
here. With ``cache=True`` it changes two things in numba's cache (numba.core.caching):

- **Key.** numba keys an entry on the text of the one file that defines the function. The
  compiled code also holds every function that function calls, from other files: when
  steppers/core/linalg.py changes and constrained.py does not, numba serves the old
  constrained.solve_rows with the old Cholesky solve inside, without a word
  (tests/test_jit_cache.py). For a function defined in the package, the entry's stamp also holds the
  hashes of the module's source closure (sources.source_closure: every package file it imports,
  transitively), so a change in any of them compiles it again. Generated modules and the portable
  glue need no more than numba's own key: their text carries the hashes of the package files they
  compile (codegen/keys.py, jit/portable.py).
- **Failure.** An entry that cannot be loaded or saved (truncated, garbage, written by something
  else) is a cache miss: the entry is removed, the function compiled again, and one warning line
  printed per source file.

The closure key reaches into numba's cache (FunctionCache, its index file's ``_source_stamp``):
``closure_cache_unsupported`` checks those on first use. When they are not as expected, a
package function is compiled without numba's cache (numba's own key could serve a stale entry),
with one warning line; any error while making the stamp is a cache miss, never a hit.

An uncached function of the stepper library (CALLEE_MODULES) is compiled without numba's
CPython and cfunc wrappers, which only a call from Python or a first-class function value would
use; a call from Python still works, through a twin compiled on first use (jit.callee).

Every dispatcher made here compiles inside jit.speedups.compiling (the speedups' scope).

numba is imported on first use, so importing this module costs nothing.
"""

from __future__ import annotations

import functools
import glob
import json
import sys
from pathlib import Path

from .sources import module_name, source_closure, source_hashes
from . import speedups


def njit(*args, **kwargs):
    """``numba.njit(**kwargs)``, usable as ``@njit`` or ``@njit(...)``; with ``cache=True`` the
    cache is keyed and guarded as the module docstring says, and an uncached function of the
    stepper library is compiled for jitted callers only (compiled_for_jitted_callers, jit.callee).
    The dispatcher compiles inside jit.speedups.compiling."""
    import numba

    def decorate(fn):
        options = dict(kwargs)
        if compiled_for_jitted_callers(fn, options):
            from .callee import callee_dispatcher
            return speedups.scope(callee_dispatcher(fn, options))
        package = options.get("cache") and module_name(fn.__code__.co_filename) is not None
        if package and closure_cache_unsupported() is not None:
            speedups.fallback("closure_cache", closure_cache_unsupported())
            options["cache"] = False
        return speedups.scope(_guard_cache(numba.njit(**options)(fn)))

    if args:                                   # used as @njit without arguments
        return decorate(args[0])
    return decorate


@functools.lru_cache(maxsize=None)
def closure_cache_unsupported():
    """None when numba's cache has what the closure key and the miss-on-error guard use, else
    why not (then a package function is compiled uncached)."""
    import inspect
    try:
        from numba.core import caching
        if not all(hasattr(caching.FunctionCache, n) for n in ("load_overload", "save_overload")):
            return "numba's FunctionCache lacks load_overload/save_overload"
        if "self._cache_file" not in inspect.getsource(caching.Cache.__init__):
            return "numba's Cache no longer keeps _cache_file"
        if "_source_stamp" not in inspect.getsource(caching.IndexDataCacheFile._load_index):
            return "numba's cache index no longer checks _source_stamp"
    except Exception as exc:
        return f"{type(exc).__name__}: {exc}".splitlines()[0]
    return None


#: Package modules (relative to lagrange_gen) whose uncached functions only jitted code calls.
CALLEE_MODULES = ("steppers.",)


def compiled_for_jitted_callers(fn, options) -> bool:
    """Whether ``fn`` (decorated with numba ``options``) is compiled without numba's wrappers:
    it is defined in CALLEE_MODULES and not cached (a cached function is loaded through its
    wrapper). Only when $LAGRANGE_GEN_SPEEDUPS selects callee and numba takes its options."""
    if options.get("cache"):
        return False
    name = module_name(fn.__code__.co_filename) or ""
    return any(name == module or (module.endswith(".") and name.startswith(module))
               for module in CALLEE_MODULES) and speedups.enabled("callee")


def closure_stamp(path) -> str:
    """JSON {package file: sha256 prefix} of the source closure of the package module at
    ``path``; what a cache entry of a function defined there is valid for."""
    return json.dumps(source_hashes(source_closure([module_name(path)])), sort_keys=True)


def _guard_cache(dispatcher):
    try:
        from numba.core.caching import FunctionCache
    except ImportError:        # closure_cache_unsupported said so: package functions uncached
        return dispatcher
    cache = getattr(dispatcher, "_cache", None)
    if type(cache) is not FunctionCache:       # not cached (NullCache), or already guarded
        return dispatcher
    source = dispatcher.py_func.__code__.co_filename
    if module_name(source) is None:
        cache.__class__ = miss_on_error_cache_class()
    else:
        cache.__class__ = closure_keyed_cache_class()
        cache.closure_source = source
    return dispatcher


@functools.lru_cache(maxsize=None)
def miss_on_error_cache_class():
    """numba's FunctionCache whose load/save failures are cache misses (defined on first use, so
    that numba is imported only when something is jitted)."""
    from numba.core.caching import FunctionCache

    class MissOnErrorCache(FunctionCache):
        def load_overload(self, sig, target_context):
            try:
                return super().load_overload(sig, target_context)
            except Exception as exc:      # an unreadable entry: remove it and compile again
                _discard_entry(self, exc)
                return None

        def save_overload(self, sig, data):
            try:
                super().save_overload(sig, data)
            except Exception as exc:      # the compiled function works; only the cache failed
                _discard_entry(self, exc)

    return MissOnErrorCache


@functools.lru_cache(maxsize=None)
def closure_keyed_cache_class():
    """MissOnErrorCache of a package function, whose stamp also holds closure_stamp of the file
    that defines it (``closure_source``, set by _guard_cache)."""

    class ClosureKeyedCache(miss_on_error_cache_class()):
        # The stamp is made on the first load or save, not at decoration: reading the closure
        # costs milliseconds per module, and most processes load a glue that already holds
        # these functions without touching their caches.
        closure_source = None

        # False once the stamp could not be made: then nothing is loaded or saved
        stamped = None

        def _stamp_closure(self) -> bool:
            if self.stamped is None:
                try:
                    # numba compares this stamp with the one stored in the index file: a
                    # mismatch drops every entry of the function (IndexDataCacheFile._load_index).
                    cache_file = self._cache_file
                    stamp = (cache_file._source_stamp, closure_stamp(self.closure_source))
                    cache_file._source_stamp = stamp
                    self.stamped = True
                except Exception as exc:          # no stamp: no hit either
                    self.stamped = False
                    speedups.fallback("closure_cache", f"stamp of {self.closure_source}: "
                                      f"{type(exc).__name__}: {exc}".splitlines()[0])
            return self.stamped

        def load_overload(self, sig, target_context):
            if not self._stamp_closure():
                return None
            return super().load_overload(sig, target_context)

        def save_overload(self, sig, data):
            if self._stamp_closure():
                super().save_overload(sig, data)

    return ClosureKeyedCache


_WARNED = set()


def _discard_entry(cache, exc):
    """Delete one function's cache files (index and data; names as numba.core.caching makes
    them) and warn once per source file."""
    removed, directory = 0, "?"
    try:
        directory, base = Path(cache.cache_path), cache._impl.filename_base
        entries = [directory / f"{base}.nbi", *directory.glob(f"{glob.escape(base)}.*.nbc")]
    except Exception:            # numba's names moved: the entry stays, the load still missed
        entries = []
    for entry in entries:
        try:
            entry.unlink()
            removed += 1
        except OSError:
            pass
    source = getattr(getattr(cache, "_py_func", None), "__code__", None)
    source = source.co_filename if source else "?"
    if source not in _WARNED:
        _WARNED.add(source)
        from .compile_notice import end_open_lines
        end_open_lines()
        if _written_at_another_path(exc):
            print(f"lagrange-gen: warning: numba cache of {source} was written where the file "
                  f"was before (the project moved or was copied); removed {removed} file(s) in "
                  f"{directory} and compiling again, once", file=sys.stderr)
            return
        what = f"{type(exc).__name__}: {exc}".splitlines()[0]
        print(f"lagrange-gen: warning: numba cache of {source} unreadable ({what}); removed "
              f"{removed} file(s) in {directory} and compiling again", file=sys.stderr)


#: The start of the module name run.loader.import_generated gives a generated module (made
#: from its absolute path, so a moved file gets another name).
GENERATED_MODULE_PREFIX = "lagrange_gen_generated_"


def _written_at_another_path(exc) -> bool:
    """Whether a cache load failed because the entry names a generated module by the name it had
    at another path: numba's entries refer to the module by name."""
    return isinstance(exc, ModuleNotFoundError) and str(exc.name or "").startswith(
        GENERATED_MODULE_PREFIX)
