"""Checked calls of a generated module's kernels from Python.

A kernel indexes its arrays without bounds checks (q[1] of a 1-entry q reads past it; H[1, 1]
of a (1, 1) H writes past it). Called from a stepper, the shapes are the stepper's own; called
from Python, they are whatever the caller passed. ``check_python_calls`` gives each kernel of a
generated module a check of its arguments (kernel_abi.ARGUMENTS: float64 arrays of the module's
shapes, a real number t) that runs on a call from Python only: jitted callers call the compiled
code, not the dispatcher's ``__call__``, so a stepper pays nothing.
"""

from __future__ import annotations

import functools
import numbers

import numpy as np

from ..codegen.kernel_abi import argument_shapes, kernel_dimensions
from ..errors import SimulationError

__all__ = ["check_python_calls", "check_kernel_arguments"]


def check_python_calls(namespace):
    """Make every kernel of the generated module whose globals are ``namespace`` (its KERNELS
    and forward_dynamics) check its arguments when called from Python; returns nothing."""
    dimensions = kernel_dimensions(namespace)
    model = namespace.get("NAME", namespace.get("__name__", "module"))
    for kernel in tuple(namespace.get("KERNELS", ())) + ("forward_dynamics",):
        dispatcher = namespace.get(kernel)
        shapes = argument_shapes(kernel, dimensions)
        if shapes is None or not hasattr(dispatcher, "overloads"):      # NUMBA_DISABLE_JIT
            continue
        dispatcher.__class__ = _checked_class(type(dispatcher))
        dispatcher.python_call_check = functools.partial(check_kernel_arguments,
                                                         f"{model}.{kernel}", shapes)


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


@functools.lru_cache(maxsize=None)
def _checked_class(base):
    """``base`` (a numba dispatcher class) whose call from Python first runs the dispatcher's
    python_call_check. A module attribute (CheckedCPUDispatcher), so that a dispatcher pickles
    by reference; one unpickled elsewhere has no check and calls straight through."""

    class CheckedKernel(base):
        def __call__(self, *args, **kwargs):
            check = getattr(self, "python_call_check", None)
            if check is not None:
                check(args, kwargs)
            return super().__call__(*args, **kwargs)

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
