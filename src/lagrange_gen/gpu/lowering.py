"""Lowering a member for the CUDA target without a GPU: numba-cuda types the member function
and kernel text (member_source.py), every stepper-library function and generated kernel they
call, and lowers them to LLVM IR for the GPU; what stops there (an allocation, an unsupported
numpy call, a Python object) fails here as it would on a GPU. Only turning that IR into PTX and
running it need the CUDA toolkit and a GPU.

numba-cuda asks the current device for its compute capability when it compiles a call to
another function; with no driver there is no device, so for the duration of the check its
``get_current_device`` answers with a stand-in that has only ``compute_capability``. That
reaches into numba-cuda (numba.cuda.dispatcher.get_current_device); missing_hook says when a
numba-cuda release no longer has it.
"""

from __future__ import annotations

import contextlib

from .cuda_runtime import import_cuda, is_simulator
from .kernels import kernel_function
from .member_source import flat_settings, method_module

#: The compute capability lowered for (an A100; H100 is (9, 0)).
DEFAULT_CC = (8, 0)


def missing_hook():
    """"" when numba-cuda has what lower_member patches, else why not."""
    try:
        from numba.cuda import compiler, dispatcher
    except Exception as exc:                      # noqa: BLE001 (any import failure: say it)
        return f"numba-cuda does not import: {exc}"
    if not hasattr(dispatcher, "get_current_device"):
        return "numba.cuda.dispatcher has no get_current_device"
    if not hasattr(compiler, "compile_cuda"):
        return "numba.cuda.compiler has no compile_cuda"
    return ""


@contextlib.contextmanager
def _stand_in_device(cc):
    from numba.cuda import dispatcher

    class StandIn:
        compute_capability = cc

    real = dispatcher.get_current_device
    dispatcher.get_current_device = lambda: StandIn()
    try:
        yield
    finally:
        dispatcher.get_current_device = real


def lower_member(module, method, n_saved=0, dtype="float64", cc=DEFAULT_CC) -> str:
    """The LLVM IR of ensemble_kernel for this module and method, lowered for the CUDA target
    with compute capability cc; raises what numba-cuda raises when it cannot."""
    cuda = import_cuda()
    if is_simulator(cuda):
        raise RuntimeError("lower_member needs numba-cuda's CUDA target: unset "
                           "NUMBA_ENABLE_CUDASIM")
    from numba import float32, float64, int64, typeof, types
    from numba.cuda.compiler import compile_cuda
    kernel = kernel_function(cuda, module, method, n_saved, dtype)
    real = {"float64": float64, "float32": float32}[dtype]
    a1, a2, a3 = real[::1], real[:, ::1], real[:, :, ::1]
    settings = flat_settings(method, method_module(method).SPEC.settings())
    args = ((a2, a2, types.float64, types.float64, int64, int64, a2)
            + tuple(typeof(value) for value in settings)
            + (a1, a3, a3, a3, a3, a2, int64[:, ::1], a2))
    with _stand_in_device(cc):
        result = compile_cuda(kernel, types.void, args, cc=cc)
    return result.library.get_llvm_str()
