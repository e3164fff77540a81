"""Native kernels: a generated kernel compiled by llvmlite from the IR jit/native_ir.py writes,
without numba's front end, and cached as object code.

The portable glue (jit/portable.py) calls a model's kernels through numba first-class functions:
all it needs of a kernel is the address of a function with numba's C-wrapper ABI and its numba
signature. ``native_kernel(module, name)`` gives that object for a kernel of a generated module:
its source, and the sources of every function it calls (a sibling kernel, the Cholesky
factorization of steppers/core/linalg.py), are lowered to one LLVM module, optimized at
OPT_LEVEL for the host CPU (its name and features: a generic x86-64 target is several times
slower on the Jacobians) and compiled in this process. The object code is written to
``<folder>/<key>.o`` (jit.folders.native_dir: beside the portable glue) with its return kind
and hash beside it; the key hashes those sources,
the module constants they read, this package's IR writer, llvmlite's version, the CPU and the
optimization level, so an unchanged kernel loads in milliseconds in the next process.

A kernel outside the subset native_ir lowers raises native_ir.Unsupported; jit/portable.py then
compiles it with numba and says so in one line. $LAGRANGE_GEN_NATIVE=0 turns native kernels off
(every kernel compiled by numba, as before). Both give the same numbers to rounding
(tests/test_native_kernels.py compares every kernel of the generated models).
"""

from __future__ import annotations

import functools
import hashlib
import json
import marshal
import os
import threading
from pathlib import Path

from . import native_ir
from .env import env_flag
from .folders import write_atomic
from .native_ir import LIBM_SYMBOLS, ModuleBuilder, Unsupported, function_source

#: Environment variable that turns native kernels off ("0", "off", "no", "false").
NATIVE_ENV = "LAGRANGE_GEN_NATIVE"

#: Environment variable giving LLVM's optimization level of native kernels (0 to 3).
OPT_ENV = "LAGRANGE_GEN_NATIVE_OPT"

#: LLVM optimization level: level 1 compiles the big kernels several times faster than 2 or 3
#: and costs about what numba's kernels cost per call (reports/firstrun.md measures both).
OPT_LEVEL = 1

#: A kernel with more IR than this (bytes of its text) whose object at the default level is not
#: cached is compiled at level 0 first (tiers_allowed): LLVM's code generation at level 1 takes
#: about a second per MB of IR, at level 0 a sixth of that, for two to three times the time per
#: call, the same numbers (no fast-math: the same operations in the same order).
FAST_FIRST_BYTES = 300_000

#: The exported symbol of a kernel in its LLVM module.
EXPORT_PREFIX = "lagrange_gen_native_"

#: What a kernel returns: a float, an int (a status), a bool, or nothing.
_RETURN_KINDS = ("f", "i", "b", None)

_LOCK = threading.Lock()
_ENGINES: list = []          # every execution engine made: they own the compiled code
_KERNELS: dict = {}          # (module file, kernel name, key) -> NativeKernel


_WARNED: set = set()


def warn_numba_compiles(module, name, reason) -> None:
    """One warning line per kernel and process: kernel ``name`` of ``module`` is compiled by
    numba because it could not be lowered (``reason``)."""
    model = getattr(module, "NAME", module.__name__)
    if (model, name) not in _WARNED:
        _WARNED.add((model, name))
        import warnings
        warnings.warn(f"lagrange-gen: {model}.{name} compiled by numba (native kernels: "
                      f"{reason})", RuntimeWarning, stacklevel=3)


def enabled() -> bool:
    """Whether native kernels are on ($LAGRANGE_GEN_NATIVE)."""
    return env_flag(NATIVE_ENV, True)


def opt_level() -> int:
    """LLVM's optimization level ($LAGRANGE_GEN_NATIVE_OPT, else OPT_LEVEL)."""
    text = os.environ.get(OPT_ENV, "").strip()
    if text in ("0", "1", "2", "3"):
        return int(text)
    if text and ("opt", text) not in _WARNED:
        _WARNED.add(("opt", text))
        import warnings
        warnings.warn(f"lagrange-gen: ${OPT_ENV}={text!r} is not 0, 1, 2 or 3; LLVM's level "
                      f"{OPT_LEVEL} is used", RuntimeWarning, stacklevel=2)
    return OPT_LEVEL


@functools.lru_cache(maxsize=None)
def _llvm():
    """llvmlite's binding, with the native target initialized and the C library's math
    functions the IR may call made known to the JIT's symbol lookup."""
    import ctypes
    import ctypes.util
    import llvmlite.binding as llvm
    try:
        llvm.initialize()        # needed before llvmlite 0.45, refused (deprecated) after
    except RuntimeError:
        pass
    llvm.initialize_native_target()
    llvm.initialize_native_asmprinter()
    libm_path = ctypes.util.find_library("m")
    libm = ctypes.CDLL(libm_path) if libm_path else ctypes.CDLL(None)
    for symbol in LIBM_SYMBOLS:
        try:
            llvm.add_symbol(symbol, ctypes.cast(getattr(libm, symbol), ctypes.c_void_p).value)
        except AttributeError:        # not in this C library: a kernel calling it fails to link
            pass
    return llvm


@functools.lru_cache(maxsize=None)
def _target_machine(level: int):
    llvm = _llvm()
    target = llvm.Target.from_default_triple()
    return target.create_target_machine(cpu=llvm.get_host_cpu_name(),
                                        features=llvm.get_host_cpu_features().flatten(),
                                        opt=level, codemodel="jitdefault")


@functools.lru_cache(maxsize=None)
def _writer_hash() -> str:
    """sha256 of the IR writer and this module: a change to either is a new key."""
    digest = hashlib.sha256()
    for name in ("native_ir.py", "native.py"):
        digest.update((Path(__file__).parent / name).read_bytes())
    return digest.hexdigest()


def _closure(fn):
    """[(name, identity, constants)] of ``fn`` and every function it calls by a global name,
    each once: what a kernel's object code is made of. identity: a function of a generated
    module, that module's TEXT_SHA (the hash of its whole text, checked when it is imported:
    codegen.keys.check_current) and its code object's bytes, so a cached kernel is found
    without reading its source;
    another function, the hash of its source. constants: the int/float/bool/array values of
    the global names its code reads (its nested code objects' too)."""
    seen, out, todo = set(), [], [fn]
    while todo:
        f = todo.pop()
        py = getattr(f, "py_func", f)
        if id(py) in seen:
            continue
        seen.add(id(py))
        globs = py.__globals__
        text_sha = globs.get("TEXT_SHA") if "KEY" in globs and "check_current" in globs else None
        if isinstance(text_sha, str) and len(text_sha) == 64:
            # the text it is lowered from, and the code it runs (a function put in the
            # module's namespace by hand has the module's TEXT_SHA but code of its own)
            identity = ("module text", text_sha,
                        hashlib.sha256(marshal.dumps(py.__code__)).hexdigest())
        else:
            source, _, _ = function_source(py)
            identity = hashlib.sha256(source.encode()).hexdigest()
        constants = {}
        for name in sorted(_global_names(py.__code__) & globs.keys()):
            value = globs[name]
            if isinstance(value, (bool, int, float)):
                constants[name] = repr(value)
            elif hasattr(value, "tobytes") and hasattr(value, "dtype"):
                constants[name] = (str(value.dtype), value.shape,
                                   hashlib.sha256(value.tobytes()).hexdigest())
            elif callable(value) and (hasattr(value, "py_func") or hasattr(value, "__code__")):
                todo.append(value)
        out.append((f"{py.__module__}.{py.__qualname__}", identity, sorted(constants.items())))
    return out


def _global_names(code) -> set:
    """The names ``code`` and the code objects nested in it (comprehensions) load from
    globals or as attributes (co_names): a superset of the globals it reads."""
    names = set(code.co_names)
    for const in code.co_consts:
        if hasattr(const, "co_names"):
            names |= _global_names(const)
    return names


def closure_digest(fn) -> str:
    """sha256 of _closure(fn): the part of a kernel's key that depends on its code."""
    digest = hashlib.sha256()
    for item in _closure(fn):
        digest.update(repr(item).encode())
    return digest.hexdigest()


def kernel_key(fn, arg_kinds, level, closure=None) -> str:
    """The object cache key of kernel ``fn`` compiled for ``arg_kinds`` at ``level``
    (closure: closure_digest(fn) when the caller has it)."""
    llvm = _llvm()
    import llvmlite
    digest = hashlib.sha256()
    digest.update(repr((_writer_hash(), llvmlite.__version__, llvm.get_host_cpu_name(),
                        llvm.get_host_cpu_features().flatten(), level, tuple(arg_kinds),
                        native_ir.CHUNK_STATEMENTS,
                        native_ir.LOOP_CHUNK_STATEMENTS)).encode())
    digest.update((closure or closure_digest(fn)).encode())
    return digest.hexdigest()[:32]


def kernel_arg_types(fn):
    """numba types of a kernel's arguments, from their names: t a float, the outputs that are
    always 2-D (kernel_abi.ALWAYS_2D) 2-D arrays, every other argument a 1-D array; all
    C-contiguous, as the steppers pass them (a kernel may flatten an output with reshape)."""
    import inspect
    from numba import types
    from .kernel_abi import ALWAYS_2D
    names = list(inspect.signature(fn).parameters)
    return tuple(types.float64 if a == "t" else types.float64[:, ::1] if a in ALWAYS_2D
                 else types.float64[::1] for a in names)


def lower_kernel(fn, arg_kinds, name="kernel"):
    """(LLVM IR text, return kind) of kernel ``fn`` exported as EXPORT_PREFIX + name.
    arg_kinds: per argument "t" (a double) or the array's number of dimensions."""
    builder = ModuleBuilder(name)
    ret = builder.export(fn, EXPORT_PREFIX + name, arg_kinds)
    return str(builder.module), ret


def _compile(ir_text, level):
    """Object code of ``ir_text`` optimized at ``level`` for the host CPU."""
    llvm = _llvm()
    module = llvm.parse_assembly(ir_text)
    module.verify()
    tm = _target_machine(level)
    if level > 0:
        _optimize(llvm, module, tm, level)
    return tm.emit_object(module)


def _optimize(llvm, module, tm, level):
    """LLVM's module pipeline at ``level``: the new pass manager where llvmlite has it, else
    the legacy PassManagerBuilder (llvmlite < 0.44, with numba 0.59 and 0.60)."""
    if hasattr(llvm, "create_pass_builder"):
        pto = llvm.create_pipeline_tuning_options(speed_level=level)
        # a kernel's loops run over a handful of columns: vectorizing them across iterations
        # costs compile time (a fifth of a humanoid Jacobian's) and wins nothing
        pto.loop_vectorization = False
        pto.slp_vectorization = False
        pb = llvm.create_pass_builder(tm, pto)
        pm = pb.getModulePassManager()
        pm.run(module, pb)
        return
    pmb = llvm.create_pass_manager_builder()
    pmb.opt_level = level
    pmb.loop_vectorize = False
    pmb.slp_vectorize = False
    pm = llvm.create_module_pass_manager()
    tm.add_analysis_passes(pm)
    pmb.populate(pm)
    pm.run(module)


def _load_object(obj: bytes, symbol: str) -> int:
    """Address of ``symbol`` in object code ``obj``, loaded into a new execution engine that
    lives as long as the process."""
    llvm = _llvm()
    empty = llvm.parse_assembly("")
    engine = llvm.create_mcjit_compiler(empty, _target_machine(0))
    engine.add_object_file(llvm.ObjectFileRef.from_data(obj))
    engine.finalize_object()
    address = engine.get_function_address(symbol)
    if not address:
        raise Unsupported(f"the object code has no symbol {symbol}")
    _ENGINES.append(engine)
    return address


@functools.lru_cache(maxsize=None)
def _native_kernel_class():
    from numba.experimental.function_type import WrapperAddressProtocol

    class NativeKernel(WrapperAddressProtocol):
        """A generated kernel compiled by llvmlite, as a numba first-class function: the
        address of its function with numba's C-wrapper ABI, and its numba signature."""

        #: CPU seconds its lowering and LLVM compile took (when it was compiled, in this
        #: process or the one that filled the cache): what the same kernel would cost numba
        #: several times over (run/fixed_driver.py weighs the specialized compile by it)
        compile_seconds = 0.0

        def __init__(self, dispatcher, name, address, signature, key, seconds, cached):
            # the generated kernel it was lowered from: the interpreted tier runs its Python
            self.dispatcher = dispatcher
            self.name, self.address, self.sig = name, address, signature
            self.key, self.seconds, self.cached = key, seconds, cached

        def __wrapper_address__(self):
            return self.address

        def signature(self):
            return self.sig

        def __repr__(self):
            return f"<native kernel {self.name} at {self.address:#x}>"

        def python_call(self):
            """A Python callable running the kernel: call(*args) with the kernel's arguments
            (C-contiguous float64 arrays of its shapes, t a float: jit.python_calls checks
            them), through native_calls' caller of its return kind (compiled once per
            installation, not per model)."""
            if self._python_call is None:
                from .native_calls import CALLERS
                caller = CALLERS.get((self.ret_kind, len(self.sig.args)))
                if caller is None:
                    raise Unsupported(f"no Python caller of {len(self.sig.args)} arguments")
                self._python_call = functools.partial(caller, self.address)
            return self._python_call

        _python_call = None

    return NativeKernel


def _signature(ret, arg_types):
    from numba import types
    restype = {"f": types.float64, "i": types.int64, "b": types.boolean, None: types.none}[ret]
    return restype(*arg_types)


def _read_object(folder: Path, key: str):
    """(object code, return kind, compile seconds) of ``key`` in the object cache, or None when
    it is missing, unreadable or not what its meta says (a truncated or foreign file must not
    reach LLVM's loader, which aborts the process)."""
    try:
        meta = json.loads((folder / f"{key}.json").read_text())
        obj, ret = (folder / f"{key}.o").read_bytes(), meta["ret"]
        if hashlib.sha256(obj).hexdigest() != meta["sha256"] or ret not in _RETURN_KINDS:
            return None
        return obj, ret, float(meta.get("seconds", 0.0))
    except (OSError, ValueError, KeyError, TypeError):
        return None


def _write_object(folder: Path, key: str, name: str, obj: bytes, ret, seconds: float) -> None:
    try:
        # the object first: a reader trusts an object only through its meta's hash
        write_atomic(folder / f"{key}.o", obj)
        write_atomic(folder / f"{key}.json", json.dumps({
            "ret": ret, "kernel": name, "sha256": hashlib.sha256(obj).hexdigest(),
            "seconds": round(seconds, 4)}).encode())
    except OSError:          # an unwritable cache: compiled again next time
        pass


def tiers_allowed(level: int) -> bool:
    """Whether a big kernel whose level-``level`` object is not cached may run at level 0 while
    a background process compiles it at ``level`` (native_background): only at the default
    level (not one set by $LAGRANGE_GEN_NATIVE_OPT) and only where background compiles are
    allowed (else nothing would ever compile the better object and every run would keep the
    slower one)."""
    from .background import background_enabled
    return level > 0 and not os.environ.get(OPT_ENV, "").strip() and background_enabled()


def native_kernel(module, name, folder: Path, level=None):
    """The kernel ``name`` of generated ``module`` compiled natively (a NativeKernel), from the
    object cache in ``folder`` when it holds it (jit.folders.native_dir). Raises
    native_ir.Unsupported when the kernel is outside the subset, or llvmlite lacks what is used
    (then the caller compiles it with numba).

    level: LLVM's level, exactly (default opt_level(): then a big kernel whose object at that
    level is not cached yet is compiled at level 0 (tiers_allowed, FAST_FIRST_BYTES): its ``level`` is then 0 and ``wanted`` the
    default level, which native_background.compile_later asks a background process for)."""
    import time
    from numba import types
    fn = getattr(module, name)
    py = getattr(fn, "py_func", fn)
    arg_types = kernel_arg_types(fn)
    arg_kinds = tuple("t" if ty == types.float64 else ty.ndim for ty in arg_types)
    requested, level = level, opt_level() if level is None else level
    try:
        closure = closure_digest(fn)
        key = kernel_key(fn, arg_kinds, level, closure)
    except Unsupported:
        raise
    except Exception as exc:     # llvmlite's binding or a source missing: numba compiles
        raise Unsupported(f"{type(exc).__name__}: {exc}".splitlines()[0]) from None
    # a lookup at the default level may hold a level-0 kernel (tiers); one at an exact level not
    memo = (getattr(module, "__file__", None), name, key, requested is None)
    with _LOCK:
        if memo in _KERNELS:
            return _KERNELS[memo]
        start = time.perf_counter()
        found = _read_object(folder, key)
        built, tiers = level, found is None and requested is None and tiers_allowed(level)
        if tiers:                       # a level-0 object made by an earlier fast first run
            key0 = kernel_key(fn, arg_kinds, 0, closure)
            found = _read_object(folder, key0)
            if found is not None:
                key, built = key0, 0
        cached = found is not None
        if found is not None:
            obj, ret, compile_seconds = found
        else:
            cpu = time.process_time()
            name_in_ir = f"{name}_{key[:16]}"
            ir_text, ret = lower_kernel(py, arg_kinds, name_in_ir)
            if tiers and len(ir_text) > FAST_FIRST_BYTES:
                key, built = key0, 0
                # the same IR under the level-0 key's symbol (a token of its own in the text)
                ir_text = ir_text.replace(f"{EXPORT_PREFIX}{name_in_ir}",
                                          f"{EXPORT_PREFIX}{name}_{key[:16]}")
            try:
                obj = _compile(ir_text, built)
            except Exception as exc:        # LLVM refused the IR: a bug here, numba compiles
                raise Unsupported(f"LLVM: {exc}".splitlines()[0]) from None
            compile_seconds = time.process_time() - cpu
            _write_object(folder, key, name, obj, ret, compile_seconds)
        symbol = f"{EXPORT_PREFIX}{name}_{key[:16]}"
        try:
            address = _load_object(obj, symbol)
        except Unsupported:
            raise
        except Exception as exc:
            raise Unsupported(f"loading the object code: {exc}".splitlines()[0]) from None
        kernel = _native_kernel_class()(fn, name, address, _signature(ret, arg_types), key,
                                        time.perf_counter() - start, cached)
        kernel.compile_seconds = compile_seconds
        kernel.ret_kind = ret
        kernel.level, kernel.wanted = built, level
        _KERNELS[memo] = kernel
        return kernel
