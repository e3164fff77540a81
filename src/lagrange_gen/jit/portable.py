"""Portable glue: one compiled copy of each stepper for every model.

The generated ``run_<method>`` (codegen/glue.py) reaches the model's kernels through the
generated module, a numba compile-time constant: numba inlines the kernels into the stepper and
compiles the whole stepper library again for every model (seconds to tens of seconds on first
use). The portable glue ``run_<method>(kern, n_saved, ...)`` is the same loop (run_loop.run_loop or
adaptive.run_adaptive) with the same method module, but ``kern`` is a named tuple of
first-class functions (the addresses of the model's compiled kernels, typed by numba as
``FunctionType(signature)``) and of the module constants the method reads. Its numba type is
the same for every model, so the stepper is compiled once per method and then loaded from
numba's cache for every model: a model just written compiles only its own kernels.

The price is a call through a pointer per kernel evaluation, without inlining across kernels (ns per
step of both loops: ``lagrange-gen bench speed``, reports/speed.md). The results are the same
floating-point operations in the same order, so a portable run equals the specialized run bit for
bit (tests/test_portable.py checks every method). simulate(jit="auto") runs the specialized glue
when numba's cache already holds it, and otherwise starts portable and switches to the specialized
glue between chunks when the run is long enough to pay for its compile (run/fixed_driver.py).

Layout: the portable glue sources (codegen.glue.portable_glue_source) are written to
``portable_dir()/<library hash>/`` (jit/folders.py); the hash covers every package file the glue
compiles, so a changed library gives new files and numba never loads a stale entry (numba's
cache checks only the glue file itself). A version directory no process has used for UNUSED_DAYS is removed when
a new one is made (remove_unused_versions), so upgrades do not pile up compiled glue.

Over 300 lines with its documentation (a fifth of the module): the kernel table, its cache
directory and the choice between portable and specialized glue share the table's type.
"""

from __future__ import annotations

import collections
import functools
import hashlib
import os
import sys
from pathlib import Path

from .folders import (DIR_ENV, UNUSED_DAYS, import_file, native_dir, portable_dir,  # noqa: F401 (the folders of the glue)
                      remove_unused_versions, write_in_version)

#: The values of simulate(jit=...).
JIT_MODES = ("auto", "specialized", "portable")

#: Environment variable giving simulate's jit when the call does not (the bench sets it to
#: "specialized": it measures the specialized loops unless a row says otherwise).
JIT_ENV = "LAGRANGE_GEN_JIT"


def jit_mode(jit) -> str:
    """The jit of simulate / ensemble: ``jit``, or when None $LAGRANGE_GEN_JIT, else "auto";
    SimulationError naming it when it is not one of JIT_MODES."""
    jit = jit or os.environ.get(JIT_ENV) or "auto"
    if jit not in JIT_MODES:
        from ..errors import SimulationError
        raise SimulationError(f"unknown jit={jit!r}; known: {', '.join(JIT_MODES)}")
    return jit


def _kernel_arg_types(fn):
    """numba types of a kernel's arguments (native.kernel_arg_types)."""
    from .native import kernel_arg_types
    return kernel_arg_types(fn)


@functools.lru_cache(maxsize=None)
def _function_kernel_class():
    """The FunctionKernel class (defined on first use: numba is imported only when a run
    needs it)."""
    from numba.experimental.function_type import WrapperAddressProtocol

    class FunctionKernel(WrapperAddressProtocol):
        """A generated kernel as a numba first-class function: the address of its compiled C
        wrapper for the portable argument types, or for ``args`` (numba types) when given (the
        dispatcher, kept alive here, owns it)."""

        def __init__(self, dispatcher, args=None):
            args = args or _kernel_arg_types(dispatcher.py_func)
            dispatcher.compile(args)
            result = dispatcher.overloads[args]
            self.dispatcher, self.sig = dispatcher, result.signature
            self.address = result.library.get_pointer_to_function(
                result.fndesc.llvm_cfunc_wrapper_name)

        def __wrapper_address__(self):
            return self.address

        def signature(self):
            return self.sig

    return FunctionKernel


@functools.lru_cache(maxsize=None)
def table_class(method: str):
    """The named tuple class of ``method``'s kernel table: one field per ``kern.<name>`` its
    glue reaches (codegen.needs: kernels and module constants) and N_EVENTS (the glue passes
    it to the loop), sorted. Defined in this module under a fixed name, so that numba's cache
    can pickle the type by reference."""
    from ..codegen.needs import method_needs
    from numba.core.typing.typeof import typeof_impl
    name = f"Kernels_{method}"
    cls = collections.namedtuple(name, sorted(method_needs(method) | {"N_EVENTS"}))
    cls.__module__ = __name__
    globals()[name] = cls
    typeof_impl.register(cls)(_typeof_table)
    return cls


#: {id(table): (table, its numba type)}: a kernel table is typed once (tables are cached on
#: their module and live as long as it; the table is kept here so that its id is not reused).
_TABLE_TYPES: dict = {}


def _typeof_table(table, context):
    """numba's type of a kernel table (registered for every table class): numba's own tuple
    typing, done on the first call only. numba types the arguments of every call of the glue
    in Python; typing a table of 11 first-class functions on every call would take a third of
    a short simulate() call (cProfile: 22 FunctionType constructions per call)."""
    from numba.core.typing.typeof import typeof_impl
    entry = _TABLE_TYPES.get(id(table))
    if entry is None or entry[0] is not table:
        entry = _TABLE_TYPES[id(table)] = (table, typeof_impl.dispatch(tuple)(table, context))
    return entry[1]


def kernel_table(module, method):
    """The kernel table of ``module`` for ``method`` (cached on the module): kernels as
    first-class functions (table_kernel), constants as they are."""
    tables = module.__dict__.setdefault("_PORTABLE_TABLES", {})
    if method not in tables:
        cls = table_class(method)
        tables[method] = cls(*(getattr(module, field) if field.isupper()
                               else table_kernel(module, field) for field in cls._fields))
        from .native_background import compile_later
        compile_later(module, [getattr(tables[method], field) for field in cls._fields
                               if not field.isupper()], native_dir())
    return tables[method]


def native_compile_seconds(module, method):
    """CPU seconds LLVM took to compile the native kernels of ``method``'s table on ``module``
    (recorded with their object code), or None when a kernel of the table is numba's."""
    table = kernel_table(module, method)
    total = 0.0
    for field in table._fields:
        kernel = getattr(table, field)
        if field.isupper():
            continue
        if not hasattr(kernel, "compile_seconds"):
            return None
        total += kernel.compile_seconds
    return total


def table_kernel(module, name):
    """Kernel ``name`` of ``module`` as a numba first-class function of the portable argument
    types: compiled by llvmlite from its source (jit/native.py: no numba compile, object code
    cached), else compiled by numba (FunctionKernel), with one warning line naming the kernel
    and why it could not be lowered. $LAGRANGE_GEN_NATIVE=0: always numba."""
    from . import native
    if native.enabled():
        from .native_ir import Unsupported
        try:
            return native.native_kernel(module, name, native_dir())
        except Unsupported as exc:
            native.warn_numba_compiles(module, name, exc)
    return _function_kernel_class()(getattr(module, name))


def library_hash(method: str) -> str:
    """sha256 prefix of every package file the glue of ``method`` compiles, and of the file
    that writes the glue's text (codegen/glue.py): the library version of its portable and
    specialized glue."""
    from .sources import source_closure, source_hashes
    from ..steppers.core.registry import LOOPS, spec
    loop_module = LOOPS[spec(method).adaptive][0]
    files = source_closure([f"steppers.methods.{method}", f"steppers.core.{loop_module}",
                            "steppers.core.step_api", "codegen.glue"])
    digest = hashlib.sha256(repr(sorted(source_hashes(files).items())).encode())
    return digest.hexdigest()[:16]


def glue_function(method: str, name: str):
    """The function ``name`` of ``method``'s portable glue (its file written and imported on
    first use)."""
    return getattr(_glue_module(method), name)


@functools.lru_cache(maxsize=None)
def _glue_module(method: str):
    """The module of the portable glue of ``method``: its source is written (atomically, once
    per library version) and imported under a unique module name. A directory that cannot be
    written is replaced by the per-user temporary one (folders.write_in_version); one that already
    holds this version's glue is only read (a shared, read-only install)."""
    from ..codegen.glue import portable_glue_source
    digest = library_hash(method)
    source = portable_glue_source(method, digest)
    path = write_in_version(digest, f"run_{method}.py", source)
    name = f"lagrange_gen_portable_{digest}_{method}"
    module = sys.modules.get(name)
    if module is None:
        module = import_file(name, path)
    return module


def n_saved(module, method):
    """The method's n_saved on ``module``'s model (SPEC.n_saved)."""
    from ..steppers.core.registry import spec
    return spec(method).n_saved(module.N_COORDS, module.N_CONSTRAINTS, module.N_ELEMENTS,
                                getattr(module, "N_CONTACTS", 0),
                                getattr(module, "N_NONHOLONOMIC", 0))


def _bound(module, method, function):
    """``function`` of the portable glue of ``method`` with ``module``'s kernel table and the
    method's n_saved on that model (SPEC.n_saved) passed in front of the glue arguments."""
    run, table = getattr(_glue_module(method), function), kernel_table(module, method)
    saved = n_saved(module, method)

    def bound(*args):
        return run(table, saved, *args)

    return bound


def _run_name(module, method):
    return f"run_{method}_events" if module.N_EVENTS else f"run_{method}"


def runner(module, method):
    """A callable with the arguments of ``module.run_<method>`` (codegen.glue.GLUE_ARGS or
    ADAPTIVE_GLUE_ARGS) that runs the portable glue on ``module``'s kernels."""
    return _bound(module, method, _run_name(module, method))


def glue_path(method) -> Path:
    """The file of the portable glue of ``method`` for this library version (written if
    missing)."""
    return Path(_glue_module(method).__file__)


def portable_cached(module, method, controlled=False) -> bool:
    """Whether the portable glue that runs ``method`` on ``module`` (controlled: the one with
    an input hook, controlled_runner) is compiled in this process or has entries in numba's
    cache for this library version (any entry: its kernel table's type is the same for every
    model but the constants', so an entry is taken as a hit; a wrong guess costs the compile it
    would have cost anyway)."""
    name = _controlled_name(module, method) if controlled else _run_name(module, method)
    glue = getattr(_glue_module(method), name)
    if glue.overloads:
        return True
    table_class(method)          # the index refers to the table's class: defined before it is read
    try:
        return bool(glue._cache._cache_file._load_index())
    except Exception:      # numba's cache internals moved, or no cache: not known to be cached
        return False


def _controlled_name(module, method):
    return f"run_{method}_controlled_events" if module.N_EVENTS else f"run_{method}_controlled"


def hook_arg_types():
    """numba types of the arguments of an input hook apply(c, t, q, v, p) -> changed
    (run/control.py): c, q, v and p C-contiguous float64 vectors, t a float64, as run_loop
    passes them."""
    from numba import types
    vector = types.float64[::1]
    return (vector, types.float64, vector, vector, vector)


#: {hook dispatcher: its FunctionKernel}: a hook is compiled for the pointer once per process.
_HOOK_POINTERS: dict = {}


def hook_pointer(hook):
    """The jitted input hook ``hook`` as a numba first-class function (FunctionKernel on
    hook_arg_types: compiled now, or loaded from numba's cache when the hook is cached); its
    numba type is the same for every hook, so the portable controlled glue compiled for one
    runs them all."""
    pointer = _HOOK_POINTERS.get(hook)
    if pointer is None:
        pointer = _HOOK_POINTERS[hook] = _function_kernel_class()(hook, hook_arg_types())
    return pointer


@functools.lru_cache(maxsize=None)
def no_inputs_hook():
    """A hook that writes nothing (False: no input changed): what the background compile
    (jit/first_run.py) compiles the portable controlled glue with, before any controller."""
    from .cache import njit

    @njit(error_model="numpy")
    def no_inputs(c, t, q, v, p):
        return False

    return no_inputs


def controlled_runner(module, method, hook, data):
    """A callable with the arguments of ``module.run_<method>`` that runs the portable
    controlled glue (run_<method>_controlled, codegen.glue) on ``module``'s kernels with the
    input hook ``hook`` (reached through hook_pointer) and its data ``data`` (a float64
    vector): nothing is compiled for a new hook but the hook."""
    run = getattr(_glue_module(method), _controlled_name(module, method))
    table, saved, pointer = kernel_table(module, method), n_saved(module, method), \
        hook_pointer(hook)

    def bound(*args):
        return run(table, saved, *args, pointer, data)

    return bound


def choose_controlled(jit, specialized, compiled, module, method, hook, data):
    """(glue, "specialized" or "portable") of a run whose inputs ``hook`` writes (data: its
    vector): ``specialized`` (the loop of module, method and hook, run/control.controlled_run,
    data bound; ``compiled``: whether it is compiled in this process) under jit="specialized",
    when numba lacks what the portable glue uses, and under "auto" when it is compiled already
    or the portable controlled glue is not cached (the run then compiles it as before; the
    driver starts the background compile of the portable one); else the portable controlled
    glue (controlled_runner; jit="portable" compiles it when it is not cached)."""
    if jit == "specialized" or _portable_off(jit) or (jit == "auto" and (
            compiled or not portable_cached(module, method, controlled=True))):
        return specialized, "specialized"
    return controlled_runner(module, method, hook, data), "portable"


def interpreted_runner(module, method):
    """runner's interpreted twin (jit.interpreted): the portable glue's Python code on the
    Python code of ``module``'s kernels, nothing compiled; it returns None instead of (status,
    steps, n_events) where Python cannot go on (interpreted.PYTHON_ONLY_FAILURE)."""
    from .interpreted import runner as python_runner
    glue = getattr(_glue_module(method), _run_name(module, method))
    return python_runner(glue, module, n_saved(module, method))


@functools.lru_cache(maxsize=None)
def unsupported():
    """None when numba has what FunctionKernel uses (WrapperAddressProtocol, the cfunc
    wrapper's name on a function descriptor), else why not: then every run takes the
    specialized glue (one warning line)."""
    try:
        from numba.core.funcdesc import FunctionDescriptor
        from numba.experimental.function_type import WrapperAddressProtocol
        for name in ("__wrapper_address__", "signature"):
            if not hasattr(WrapperAddressProtocol, name):
                return f"numba's WrapperAddressProtocol lacks {name}"
        if not hasattr(FunctionDescriptor, "llvm_cfunc_wrapper_name"):
            return "numba's FunctionDescriptor lacks llvm_cfunc_wrapper_name"
    except Exception as exc:
        return f"{type(exc).__name__}: {exc}".splitlines()[0]
    return None


def _portable_off(jit) -> bool:
    """Whether the portable glue cannot run (unsupported); warns once when a run wanted it."""
    reason = unsupported()
    if reason is not None and jit != "specialized":
        from .speedups import fallback
        fallback("portable", reason)
    return reason is not None


def choose(jit, specialized, module, method, args):
    """(glue, "specialized" or "portable") for a first call with ``args``: jit="specialized"
    the module's glue; "portable" the portable one; "auto" the module's glue when it runs
    ``args`` without compiling (specialized_ready), else the portable one. The module's glue
    whenever numba lacks what the portable glue uses (unsupported)."""
    if jit == "specialized" or _portable_off(jit) or (
            jit == "auto" and specialized_ready(specialized, args)):
        return specialized, "specialized"
    return runner(module, method), "portable"


def choose_ensemble(jit, specialized, module, method, args):
    """(glue, "specialized" or "portable") as choose, for ``module.ensemble_<method>`` and the
    portable ``ensemble_<method>``, which has no event code: a model with events runs the
    module's (jit="portable" is refused)."""
    if module.N_EVENTS and jit == "portable":
        from ..errors import SimulationError
        raise SimulationError(f"{module.NAME}: the portable ensemble glue has no event code and "
                              f"this model has events; use jit='auto' or 'specialized'")
    if jit == "specialized" or module.N_EVENTS or _portable_off(jit) or (
            jit == "auto" and specialized_ready(specialized, args)):
        return specialized, "specialized"
    return _bound(module, method, f"ensemble_{method}"), "portable"


#: {argument key: numba signature} and {(cache index file, signature): the index's stamp when it
#: did not hold that signature}: specialized_ready, which simulate calls on every run, types its
#: arguments once per kind of arguments and reads a cache index once per version of it.
_SIGNATURES: dict = {}
_MISSES: dict = {}
_UNSEEN = object()


def _argument_key(value):
    """What numba's type of an argument depends on, for the values simulate passes: an array's
    dtype, dimensions, layout and writability; a tuple's class and items; else the class."""
    import numpy as np
    if isinstance(value, np.ndarray):
        flags = value.flags
        return (value.dtype.str, value.ndim, flags.c_contiguous, flags.f_contiguous,
                flags.writeable, flags.aligned)
    if isinstance(value, tuple):
        return (type(value), tuple(_argument_key(v) for v in value))
    return type(value)


def _index_state(cache):
    """(path, stamp) of a numba cache's index file: stamp = (mtime, size), or None while there is
    no index (saving an entry writes it, which changes the stamp); None when numba's internals
    moved (then nothing is remembered)."""
    try:
        path = cache._cache_file._index_path
    except AttributeError:
        return None
    try:
        info = os.stat(path)
    except OSError:
        return path, None
    return path, (info.st_mtime_ns, info.st_size)


def specialized_ready(dispatcher, args) -> bool:
    """Whether the specialized glue ``dispatcher`` can run ``args`` without compiling: already
    compiled in this process, or in numba's on-disk cache (then it is loaded now, as numba's own
    first call would load it). A miss is remembered until the cache index changes (another
    process may compile the glue meanwhile): a caller running simulate() once per short step
    (a controller on the cart pole, ``lagrange-gen bench stepapi``) would otherwise look the
    glue up in numba's cache on every call, hundreds of microseconds each."""
    try:
        key = tuple(_argument_key(a) for a in args)
        sig = _SIGNATURES.get(key)
        if sig is None:
            sig = _SIGNATURES[key] = tuple(dispatcher.typeof_pyval(a) for a in args)
        if sig in dispatcher.overloads:
            return True
        cache = getattr(dispatcher, "_cache", None)
        if cache is None:
            return False
        index = _index_state(cache)
        if index is not None and index[1] is None:
            # no index file, so no entry: numba's lookup would first set up its target (a
            # second of imports, scipy's included) only to miss
            return False
        if index is not None and _MISSES.get((index[0], sig), _UNSEEN) == index[1]:
            return False
        result = cache.load_overload(sig, dispatcher.targetctx)
        if result is None:
            if index is not None:
                _MISSES[(index[0], sig)] = index[1]
            return False
        # as numba's Dispatcher.compile does with a cache hit
        dispatcher.targetctx.insert_user_function(result.entry_point, result.fndesc,
                                                  [result.library])
        dispatcher.add_overload(result)
        return True
    except Exception:       # numba internals moved: treat as not cached (portable runs)
        return False
