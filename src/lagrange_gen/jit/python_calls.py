"""Checked calls of a generated module's kernels from Python.

A kernel indexes its arrays without bounds checks (q[1] of a 1-entry q reads past it; H[1, 1]
of a (1, 1) H writes past it). Called from a stepper, the shapes are the stepper's own; called
from Python, they are whatever the caller passed. ``check_python_calls`` gives each kernel of a
generated module a check of its arguments (kernel_abi.ARGUMENTS: float64 arrays of the module's
shapes, a real number t) that runs on a call from Python only: jitted callers call the compiled
code, not the dispatcher's ``__call__``, so a stepper pays nothing. A checked call from Python
runs the kernel's native twin (jit/native.py) where it has one, so a Python caller compiles
nothing with numba.
"""

from __future__ import annotations

import functools
import numbers

import numpy as np

from .kernel_abi import argument_shapes, kernel_dimensions
from ..errors import SimulationError

__all__ = ["check_python_calls", "check_kernel_arguments", "unchecked"]


def check_python_calls(namespace):
    """Make every kernel of the generated module whose globals are ``namespace`` (its KERNELS
    and forward_dynamics) check its arguments when called from Python, and give the module
    ``_forward_dynamics_unchecked``, the call without the check, for its ``accelerations``
    (which makes the arguments itself); returns nothing."""
    dimensions = kernel_dimensions(namespace)
    model = namespace.get("NAME", namespace.get("__name__", "module"))
    for kernel in tuple(namespace.get("KERNELS", ())) + ("forward_dynamics",):
        dispatcher = namespace.get(kernel)
        shapes = argument_shapes(kernel, dimensions)
        if shapes is None or not hasattr(dispatcher, "overloads"):      # NUMBA_DISABLE_JIT
            continue
        dispatcher.__class__ = _checked_class(type(dispatcher))
        dispatcher.python_call_fast = _fast_check(shapes)
        dispatcher.python_call_check = functools.partial(_full_check, f"{model}.{kernel}", shapes)
        dispatcher.python_call_native = _NativeCall(namespace, kernel)
    if "forward_dynamics" in namespace:
        namespace["_forward_dynamics_unchecked"] = unchecked(namespace["forward_dynamics"])


def unchecked(kernel):
    """``kernel``'s call without the argument check, for a loop of the package over arrays it
    made itself (one call per saved row: the check costs a few microseconds a call): through
    its native kernel where it has one (_NativeCall), else numba's. A kernel without the check
    is returned as it is."""
    base = getattr(type(kernel), "unchecked_base", None)
    if base is None:
        return kernel
    numba_call = functools.partial(base.__call__, kernel)
    native = getattr(kernel, "python_call_native", None)
    chosen = []

    def call(*args):
        # the first call chooses (a module's import makes this before the kernel is needed)
        if not chosen:
            resolved = native.resolve() if native is not None else None
            chosen.append(resolved if resolved is not None else numba_call)
        return chosen[0](*args)

    return call


def check_kernel_arguments(kernel, shapes, args, kwargs):
    """Refuse (SimulationError, one line naming the kernel and the argument) a call whose
    arguments are not those of ``shapes`` [(name, shape or None)]: a float64 ndarray of that
    shape for an array, a real number for the time. Returns the arguments in order."""
    if kwargs:
        names = [name for name, _ in shapes]
        unknown = sorted(set(kwargs) - set(names))
        if unknown:
            raise SimulationError(f"{kernel}: unknown argument(s) {', '.join(unknown)} "
                                  f"(arguments: {', '.join(names)})")
        args = tuple(args) + tuple(kwargs[name] for name in names[len(args):] if name in kwargs)
    if len(args) != len(shapes):
        raise SimulationError(f"{kernel}: takes {len(shapes)} arguments "
                              f"({', '.join(name for name, _ in shapes)}), got {len(args)}")
    for value, (name, shape) in zip(args, shapes):
        if shape is None:
            if not isinstance(value, numbers.Real) or isinstance(value, (bool, np.bool_)):
                raise SimulationError(f"{kernel}: argument {name!r} must be a real number, "
                                      f"got {value!r}")
        elif not (type(value) is np.ndarray and value.dtype == np.float64 and value.shape == shape):
            got = (f"a {value.dtype} array of shape {value.shape}" if isinstance(value, np.ndarray)
                   else type(value).__name__)
            raise SimulationError(f"{kernel}: argument {name!r} must be a float64 array of shape "
                                  f"{shape}, got {got}")
    return args


_FLOAT64 = np.dtype(np.float64)


def _full_check(kernel, shapes, args, kwargs):
    """check_kernel_arguments for a call the fast check did not pass: it names what is wrong,
    or accepts what the kernel takes all the same (an int t, keyword arguments); returns the
    arguments in order."""
    args = check_kernel_arguments(kernel, shapes, args, kwargs)
    # a real t of another type (an int, numpy's float64) as the float the native call takes
    return tuple(float(a) if shape is None else a for a, (_, shape) in zip(args, shapes))


class _NativeCall:
    """A kernel's call from Python through its native kernel (jit/native.py: compiled by LLVM,
    called through jit/native_calls.py), so that a Python caller (accelerations, the energy check after a
    run, linearize) compiles nothing with numba: made on the first call, from the generated
    module's namespace. None where native kernels are off or the kernel is outside what
    native_ir lowers (then numba compiles it, one line says why). A call whose arrays are not
    C-contiguous and writable goes to numba, which takes any layout."""

    def __init__(self, namespace, kernel):
        self.namespace, self.kernel, self.call = namespace, kernel, False

    def resolve(self):
        if self.call is False:
            self.call = None
            from . import native
            if native.enabled():
                import sys
                module = sys.modules.get(self.namespace.get("__name__"))
                if module is not None and getattr(module, self.kernel, None) is not None:
                    from .native_ir import Unsupported
                    from .folders import native_dir
                    try:
                        kernel = native.native_kernel(module, self.kernel, native_dir())
                        self.call = kernel.python_call()
                        from .native_background import compile_later
                        compile_later(module, [kernel], native_dir())
                    except Unsupported as exc:
                        native.warn_numba_compiles(module, self.kernel, exc)
        return self.call

    def __call__(self, args, trusted=False):
        """The kernel's result, or _NUMBA when numba should run this call; ``trusted``: the
        package's own arrays (unchecked), known C-contiguous and writable."""
        call = self.call if self.call is not False else self.resolve()
        if call is None:
            return _NUMBA
        if not trusted:
            for value in args:
                if type(value) is np.ndarray:
                    flags = value.flags
                    if not (flags.c_contiguous and flags.writeable):
                        return _NUMBA
        return call(*args)


_NUMBA = object()


def _fast_check(shapes):
    """fast(args) -> True for the common call: positional arguments, float64 ndarrays of the
    right shapes (native byte order), a float t. One expression written out for the kernel's
    arguments, so that the check costs a few hundred nanoseconds; anything else is False (then
    _full_check decides)."""
    terms = [f"len(a) == {len(shapes)}"]
    constants = {"ndarray": np.ndarray, "float64": _FLOAT64}
    for i, (_, shape) in enumerate(shapes):
        if shape is None:
            terms.append(f"type(a[{i}]) is float")
        else:
            constants[f"shape{i}"] = shape
            terms.append(f"type(a[{i}]) is ndarray and a[{i}].shape == shape{i} and a[{i}].dtype is float64")
    source = "def fast(a):\n    return " + " and ".join(terms) + "\n"
    namespace = dict(constants)
    exec(compile(source, "<kernel argument check>", "exec"), namespace)
    return namespace["fast"]


@functools.lru_cache(maxsize=None)
def _checked_class(base):
    """``base`` (a numba dispatcher class) whose call from Python first runs the dispatcher's
    python_call_fast and, when that does not pass, python_call_check. A module attribute (CheckedCPUDispatcher), so that a dispatcher pickles
    by reference; one unpickled elsewhere has no check and calls straight through."""

    call = base.__call__

    class CheckedKernel(base):
        def __call__(self, *args, **kwargs):
            if kwargs or not self.python_call_fast(args):
                args, kwargs = self.python_call_check(args, kwargs), {}
            native = getattr(self, "python_call_native", None)
            if native is not None:
                result = native(args)
                if result is not _NUMBA:
                    return result
            return call(self, *args, **kwargs)

    CheckedKernel.unchecked_base = base
    name = f"Checked{base.__name__}"
    CheckedKernel.__qualname__ = CheckedKernel.__name__ = name
    CheckedKernel.__module__ = __name__
    globals()[name] = CheckedKernel
    return CheckedKernel


def __getattr__(name):
    """CheckedCPUDispatcher made on first use (an unpickling in a fresh process asks for it)."""
    if name == "CheckedCPUDispatcher":
        from numba.core.registry import CPUDispatcher
        return _checked_class(CPUDispatcher)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
