"""GPU ensembles against the CPU ensemble: member-steps per second of
lagrange_gen.ensemble(device="cuda") and of the CPU ensemble on every core in the same run, the
largest difference between their final states, and the GPU's first compile.

Work (issue 30): the cart pendulum with 2^20 members and an 8-link pendulum
(models/n_link_pendulum.py, n = 8) with 2^17 members, rk4, h = 1e-3, 1,000 steps, saving only the
first and the last state; float64, and the cart pendulum again in float32 with its difference
from float64. Members differ in q0, v0 (and the cart's spring k). --quick: 2^14 and 2^11 members.

Without a usable GPU (numba-cuda missing, no driver, or NUMBA_ENABLE_CUDASIM=1: the simulator is
not a GPU) it says so and measures nothing.

Run: ``lagrange-gen bench gpu [--quick]`` (writes reports/gpu.md).
"""

from __future__ import annotations

import os
import platform
import time
from pathlib import Path

import numpy as np

from .common import write_report

H_STEP, N_STEPS = 1e-3, 1000

#: (label, model file, build options, log2 members, log2 members with --quick)
WORK = (("cart pendulum", "cart_pendulum.py", None, 20, 14),
        ("8-link pendulum", "n_link_pendulum.py", {"n": 8}, 17, 11))


def _members(module, M, seed=0):
    rng = np.random.default_rng(seed)
    n = module.N_COORDS
    run = dict(q0=rng.uniform(-0.5, 0.5, (M, n)), v0=rng.uniform(-1.0, 1.0, (M, n)))
    if "k" in module.PARAMS:
        run["params"] = {"k": rng.uniform(5.0, 15.0, M)}
    return run


def measure(module, M, n_steps=N_STEPS, h=H_STEP, method="rk4"):
    """One row: GPU float64 (and float32) against the CPU ensemble on the same members."""
    from ..run.ensemble import ensemble
    run = dict(_members(module, M), t_end=n_steps * h, h=h, save_every=n_steps)
    start = time.perf_counter()
    gpu = ensemble(module, method, device="cuda", **run)
    gpu_call = time.perf_counter() - start
    single = ensemble(module, method, device="cuda", dtype="float32", **run)
    cpu = ensemble(module, method, **run)
    cpu = min((cpu, ensemble(module, method, **run)), key=lambda r: r.wall_time)
    scale = max(1.0, float(np.nanmax(np.abs(cpu.q[:, -1]))))
    steps = M * n_steps
    return dict(M=M, device=gpu.device, gpu_s=gpu.wall_time, gpu_call_s=gpu_call,
                compile_s=gpu.compile_time, cpu_s=cpu.wall_time,
                gpu_rate=steps / gpu.wall_time, cpu_rate=steps / cpu.wall_time,
                diff=float(np.nanmax(np.abs(gpu.q[:, -1] - cpu.q[:, -1]))) / scale,
                f32_rate=steps / single.wall_time,
                f32_diff=float(np.nanmax(np.abs(single.q[:, -1] - cpu.q[:, -1]))) / scale,
                failed=int((~gpu.ok).sum()), cpu_failed=int((~cpu.ok).sum()))


def run_gpu_bench(report, models_dir="models", quick=False, gen_dir="generated"):
    """Measure WORK on the GPU and the CPU and write ``report``; on a machine without a usable
    GPU print why and write nothing. Returns the rows (None without a GPU)."""
    from ..gpu.cuda_runtime import gpu_present
    present, what = gpu_present()
    if not present:
        print(f"bench gpu: no GPU found, nothing measured ({what})")
        return None
    from ..run.simulate import load_module
    rows = []
    for label, stem, options, log2, log2_quick in WORK:
        module = load_module(str(Path(models_dir) / stem), gen_dir, "rk4", options=options)
        M = 2 ** (log2_quick if quick else log2)
        print(f"bench gpu: {label}, {M} members ...", flush=True)
        rows.append((label, measure(module, M)))
    lines = report_lines(rows, what, quick)
    path = write_report(report, lines)
    print("\n".join(lines))
    print(f"wrote {path}")
    return rows


def report_lines(rows, device, quick=False):
    """The report's lines (markdown) for rows [(label, measure(...))] measured on ``device``."""
    import numba
    lines = [
        "# GPU ensembles against the CPU ensemble",
        "",
        f"`lagrange-gen bench gpu{' --quick' if quick else ''}`: rk4, h = {H_STEP:g}, "
        f"{N_STEPS} steps per member, first and last state saved; member-steps per second of "
        f"the kernel run (without the copies to and from the GPU; the whole GPU call in "
        f"brackets) and of the CPU ensemble on {numba.get_num_threads()} threads "
        f"({os.cpu_count()} CPUs, {platform.processor() or platform.machine()}), best of 2 "
        f"CPU runs. GPU: {device}. Difference: the largest |q_gpu - q_cpu| at the last state "
        f"over all members, relative to max(1, |q|).",
        "",
        "| model | members | GPU member-steps/s | CPU member-steps/s | GPU / CPU | "
        "max difference | first GPU compile | float32 member-steps/s | float32 difference |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for label, r in rows:
        lines.append(
            f"| {label} | {r['M']} | {r['gpu_rate']:.3g} ({r['gpu_s']:.3g} s; call "
            f"{r['gpu_call_s']:.3g} s) | {r['cpu_rate']:.3g} ({r['cpu_s']:.3g} s) | "
            f"{r['gpu_rate'] / r['cpu_rate']:.3g}x | {r['diff']:.2g} | {r['compile_s']:.3g} s | "
            f"{r['f32_rate']:.3g} | {r['f32_diff']:.2g} |")
    failed = [f"{label}: {r['failed']} GPU / {r['cpu_failed']} CPU members failed"
              for label, r in rows if r["failed"] or r["cpu_failed"]]
    lines += ["", *(failed or ["Every member of every run reached t_end."])]
    return lines
