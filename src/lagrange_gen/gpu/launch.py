"""An ensemble's members on the GPU: device arrays, one launch (one member per thread), the copy
back into the ensemble's output arrays (lagrange_gen.run.ensemble fills the EnsembleResult
from them exactly as after a CPU run)."""

from __future__ import annotations

import math
import time

import numpy as np

from ..errors import SimulationError
from ..steppers.core import layout
from .cuda_runtime import device_name, is_simulator, load_cuda
from .kernels import DTYPES, compiled_kernel
from .member_source import THREADS_PER_BLOCK, flat_settings, refusal

#: Threads per block under the simulator (it runs one Python thread per CUDA thread of a block).
SIMULATOR_THREADS_PER_BLOCK = 8

#: float32 members stop Newton at a residual relative to max(1, |x|); below this tolerance the
#: rounding of float32 arithmetic keeps the residual above it.
FLOAT32_MIN_NEWTON_TOL = 1e-5


def check_gpu_request(module, method, dtype, config):
    """One-line SimulationError when the GPU path cannot run this request (method, model,
    dtype, a float32 Newton tolerance below its rounding); before numba-cuda is imported."""
    reason = refusal(module, method)
    if reason:
        raise SimulationError(reason)
    if dtype not in DTYPES:
        raise SimulationError(f"dtype {dtype!r}: device='cuda' runs {' or '.join(DTYPES)}")
    tol = getattr(config, "newton_tol", None)
    if dtype == "float32" and tol is not None and tol < FLOAT32_MIN_NEWTON_TOL:
        raise SimulationError(
            f"{module.NAME}, {method}: newton_tol={tol:g} is below what float32 arithmetic "
            f"reaches; pass newton_tol >= {FLOAT32_MIN_NEWTON_TOL:g} with dtype='float32'")


def run_on_gpu(module, method, q, v, p, t0, h, n_steps, save_every, config, out,
               dtype="float64"):
    """Run the members (q, v (M, n), p (M, n_params) float64) on the GPU and write their outputs
    into ``out`` (ensemble_outputs.allocate_outputs: float64 host arrays, NaN where a member
    wrote nothing). Returns (compile seconds, run seconds, device name); the run seconds are
    the launch to its end, without the copies to and from the GPU."""
    check_gpu_request(module, method, dtype, config)
    cuda = load_cuda()
    n_saved = out["extra"].shape[2]
    real = np.dtype(dtype)
    host = dict(q0=q.astype(real), v0=v.astype(real), p=p.astype(real))
    host.update({name: out[name].astype(real) for name in ("q", "v", "stats", "extra", "last")})
    host["status"] = out["status"].copy()
    rows = out["q"].shape[1]
    host["t"] = np.full(rows, np.nan, real)
    host["events"] = np.zeros((1, layout.events_size(module.N_COORDS)), real)
    _check_device_memory(cuda, module, sum(a.nbytes for a in host.values()))
    kernel = compiled_kernel(cuda, module, method, n_saved, dtype)
    threads = SIMULATOR_THREADS_PER_BLOCK if is_simulator(cuda) else THREADS_PER_BLOCK
    M = q.shape[0]
    settings = flat_settings(method, config)

    start = time.perf_counter()
    _launch(cuda, kernel, threads, _first_member(cuda, host), t0, h, 0, save_every, settings)
    compile_time = time.perf_counter() - start

    device = {name: cuda.to_device(array) for name, array in host.items()}
    start = time.perf_counter()
    _launch(cuda, kernel, threads, device, t0, h, n_steps, save_every, settings, M)
    run_time = time.perf_counter() - start
    for name in ("q", "v", "stats", "extra", "last"):
        out[name][...] = device[name].copy_to_host()
    out["status"][...] = device["status"].copy_to_host()
    return compile_time, run_time, device_name(cuda)


def _launch(cuda, kernel, threads, arrays, t0, h, n_steps, save_every, settings, M=None):
    """One launch over the members of ``arrays`` (host or device arrays), waited for."""
    M = arrays["q0"].shape[0] if M is None else M
    blocks = max(1, math.ceil(M / threads))
    a = arrays
    kernel[blocks, threads](a["q0"], a["v0"], float(t0), float(h), int(n_steps),
                            int(save_every), a["p"], *settings, a["t"], a["q"], a["v"],
                            a["stats"], a["extra"], a["last"], a["status"], a["events"])
    cuda.synchronize()


def _first_member(cuda, host):
    """Member 0's arrays, on the device: a launch on them with no steps compiles the kernel
    (its argument types are those of the full launch) without touching the ensemble's
    outputs."""
    return {name: cuda.to_device(np.ascontiguousarray(
        array if name in ("t", "events") else array[:1])) for name, array in host.items()}


def _check_device_memory(cuda, module, need):
    """One-line SimulationError when the device arrays do not fit in the GPU's free memory."""
    if is_simulator(cuda):
        return
    free, total = cuda.current_context().get_memory_info()
    if need > 0.9 * free:
        raise SimulationError(
            f"{module.NAME}: the ensemble needs {need / 2**30:.2f} GiB on the GPU and "
            f"{free / 2**30:.2f} GiB of {total / 2**30:.2f} GiB are free; save fewer rows "
            f"(a larger save_every) or run fewer members per call")
