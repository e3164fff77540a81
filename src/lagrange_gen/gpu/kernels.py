"""The member function and kernel of member_source.py compiled for the GPU, or for numba's CUDA
simulator; memoized per (module, method, dtype) in this process.

For the GPU, the member is a CUDA device function (``cuda.jit(device=True)``); the functions it
calls (the method's prepare and step, run_loop.steps, the generated kernels: all numba CPU
dispatchers) are compiled by numba-cuda for the CUDA target from their Python source when the
kernel is first compiled. Under the simulator the kernel runs in Python and the member is
compiled by numba for the CPU with numpy arrays for its local arrays (the simulator runs
device functions as Python, and numba types the generated module as a constant only inside
compiled code); its device arrays are passed to it as numpy views.
"""

from __future__ import annotations

import linecache
import math
import types

import numpy as np

from ..steppers.core import layout, run_loop, work
from ..steppers.core.layout import STAT_WORK
from ..steppers.core.output import save_row, write_last
from ..steppers.core.state_checks import check_state
from ..steppers.core.status import NON_FINITE, OK
from .cuda_runtime import is_simulator
from .member_source import kernel_source, member_source, method_module

#: (module file, module KEY, method, n_saved, dtype name, simulator) -> the launchable kernel.
_COMPILED = {}

#: ``cuda`` of a member compiled for the CPU: ``cuda.local.array(shape, dtype)`` is np.empty
#: there (numba types a module's attributes as constants, as numba-cuda types cuda.local).
CUDA_ON_CPU = types.ModuleType("lagrange_gen_cuda_on_cpu")
CUDA_ON_CPU.local = types.ModuleType("lagrange_gen_cuda_on_cpu.local")
CUDA_ON_CPU.local.array = np.empty

#: numpy dtypes the GPU path runs in.
DTYPES = ("float64", "float32")


def member_namespace(cuda, module, method, dtype, for_cpu):
    """The names member_source's text reads: numba-cuda and numba types for the GPU, a
    ``cuda.local.array`` that is np.empty and numpy dtypes for a member compiled for the CPU
    (for_cpu)."""
    import numba
    stepper = method_module(method)
    names = dict(
        math=math, cuda=CUDA_ON_CPU if for_cpu else cuda, kern=module, method=stepper, Workspace=stepper.Workspace,
        WorkWorkspace=work.Workspace, Settings=stepper.SPEC.settings, steps=run_loop.steps,
        check_state=check_state, save_row=save_row, write_last=write_last, work=work,
        layout=layout, STAT_WORK=STAT_WORK, OK=OK, NON_FINITE=NON_FINITE)
    if for_cpu:
        names.update(FLOAT=np.dtype(dtype).type, INT=np.int64)
    else:
        names.update(FLOAT=getattr(numba, dtype), INT=numba.int64)
    return names


def exec_source(source, names, label):
    """Run ``source`` in ``names`` (registered with linecache, so tracebacks show it)."""
    filename = f"<lagrange_gen.gpu {label}>"
    linecache.cache[filename] = (len(source), None, source.splitlines(True), filename)
    exec(compile(source, filename, "exec"), names)
    return names


def compiled_kernel(cuda, module, method, n_saved, dtype):
    """The kernel ``ensemble_kernel[blocks, threads](...)`` for this module, method and dtype
    (compiled on its first launch; the same object for the same arguments in this process)."""
    simulator = is_simulator(cuda)
    key = (getattr(module, "__file__", module.NAME), getattr(module, "KEY", ""), method,
           n_saved, dtype, simulator)
    if key not in _COMPILED:
        kernel = kernel_function(cuda, module, method, n_saved, dtype, simulator)
        _COMPILED[key] = cuda.jit(kernel)
    return _COMPILED[key]


def kernel_function(cuda, module, method, n_saved, dtype, member_on_cpu=False):
    """The Python function ensemble_kernel bound to its member: a CUDA device function, or
    (member_on_cpu, for the simulator) the member compiled for the CPU."""
    label = f"{module.NAME} {method} {dtype}"
    names = exec_source(member_source(module, method, n_saved),
                        member_namespace(cuda, module, method, dtype, member_on_cpu), label)
    if member_on_cpu:
        member = _numpy_views(_cpu_member(names["member"]))
    else:
        member = cuda.jit(device=True)(names["member"])
    kernel = exec_source(kernel_source(method), dict(
        cuda=cuda, member=member, Settings=method_module(method).SPEC.settings),
        f"{label} kernel")
    return kernel["ensemble_kernel"]


def _cpu_member(member):
    import numba
    return numba.njit(error_model="numpy")(member)


def _numpy_views(member):
    """``member`` called with the simulator's device arrays as numpy views (numba's CPU code
    cannot unbox them; np.asarray shares their memory)."""
    def call(*args):
        return member(*(np.asarray(a) if hasattr(a, "__array_interface__") else a
                        for a in args))
    return call
