"""Ensemble throughput: members per second of lagrange_gen.ensemble on the cart pendulum (rk4,
T = 10, h = 1e-3, 10,000 steps per member) on 1 and 2 numba threads, against a Python loop of
simulate() measured on a subset of the members (reported per member), and the overhead per chunk
of a Dask LocalCluster of two worker processes on (up to) 2,000 of the members.

Members differ in q0, v0 and the spring stiffness k. Each timing is the best of REPEATS runs
(the machine may be shared: the best run is the one least disturbed by others). The report also
states whether the 1- and 2-thread results are identical and whether the subset equals simulate
bitwise.

Run: ``lagrange-gen bench ensemble [--quick]`` (writes reports/ensemble.md).
"""

from __future__ import annotations

import os
import tempfile
import time
from pathlib import Path

import numpy as np

from .common import write_report

T_END, H_STEP, SAVE_EVERY = 10.0, 1e-3, 100
REPEATS = 3


def _members(M, seed=0):
    rng = np.random.default_rng(seed)
    q0 = rng.uniform(-0.5, 0.5, (M, 2))
    v0 = rng.uniform(-1.0, 1.0, (M, 2))
    return q0, v0, rng.uniform(5.0, 15.0, M)


def _thread_cpu():
    """{thread id: CPU seconds} of this process's threads (Linux /proc; {} elsewhere)."""
    ticks = os.sysconf("SC_CLK_TCK") if hasattr(os, "sysconf") else 100
    seconds = {}
    try:
        for tid in os.listdir("/proc/self/task"):
            with open(f"/proc/self/task/{tid}/stat") as f:
                fields = f.read().rsplit(")", 1)[1].split()
            seconds[tid] = (int(fields[11]) + int(fields[12])) / ticks
    except (OSError, IndexError, ValueError):
        return {}
    return seconds


def _subset_result(result, count):
    """The first ``count`` members of an EnsembleResult (only q is compared)."""
    from types import SimpleNamespace
    return SimpleNamespace(q=result.q[:count])


def _time_ensembles(module, q0, v0, k, threads):
    """{threads: (best wall seconds, CPU seconds / wall seconds of that run, a result)}; the
    thread counts alternate from one repeat to the next, so that load from other processes
    falls on both alike. CPU / wall is how many cores the run actually got."""
    import numba

    from ..run.ensemble import ensemble
    before = numba.get_num_threads()
    timed = {t: (float("inf"), 0.0, None) for t in threads}
    split = {}
    # compile (or load from the cache) first: the CPU windows below measure integration only
    ensemble(module, "rk4", q0=q0[:2], v0=v0[:2], params={"k": k[:2]}, t_end=T_END, h=H_STEP,
             save_every=SAVE_EVERY)
    try:
        for _ in range(REPEATS):
            for t in threads:
                numba.set_num_threads(t)
                cpu, start, per_thread = time.process_time(), time.perf_counter(), _thread_cpu()
                result = ensemble(module, "rk4", q0=q0, v0=v0, params={"k": k}, t_end=T_END,
                                  h=H_STEP, save_every=SAVE_EVERY)
                # CPU seconds of every thread over the whole call / its wall seconds
                cores = (time.process_time() - cpu) / (time.perf_counter() - start)
                after = _thread_cpu()
                if result.wall_time < timed[t][0]:
                    timed[t] = (result.wall_time, cores, result)
                    split[t] = sorted((after[k] - per_thread.get(k, 0.0) for k in after
                                       if after[k] - per_thread.get(k, 0.0) > 0.05),
                                      reverse=True)
    finally:
        numba.set_num_threads(before)
    return timed, split


def _time_simulate_loop(module, q0, v0, k, result):
    """(best seconds per member of a Python loop of simulate over the subset, cores obtained
    in that run, all members bitwise equal to the ensemble's)."""
    from ..run.simulate import simulate
    best, cores, equal = float("inf"), 0.0, True
    for _ in range(REPEATS):
        start, cpu = time.perf_counter(), time.process_time()
        trajs = [simulate(module, "rk4", q0[i], v0[i], params={"k": k[i]}, t_end=T_END,
                          h=H_STEP, save_every=SAVE_EVERY) for i in range(len(k))]
        wall = time.perf_counter() - start
        if wall / len(k) < best:
            best, cores = wall / len(k), (time.process_time() - cpu) / wall
    for i, traj in enumerate(trajs):
        equal &= np.array_equal(traj.q, result.q[i]) and np.array_equal(traj.v, result.v[i])
    return best, cores, equal


def _time_dask(module, q0, v0, k, local):
    """Wall seconds of the same members through a LocalCluster of two single-threaded worker
    processes (after a warm-up call that imports and compiles on the workers), the number of
    chunks, and whether the arrays equal the local run's; None without dask.distributed."""
    try:
        import distributed
    except ImportError:
        return None
    from ..run.ensemble import ensemble
    from ..run.ensemble_dask import chunk_size
    kwargs = dict(q0=q0, v0=v0, params={"k": k}, t_end=T_END, h=H_STEP, save_every=SAVE_EVERY)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        ensemble(module, "rk4", client=client, **{**kwargs, "q0": q0[:4], "v0": v0[:4],
                                                  "params": {"k": k[:4]}})
        best, result = float("inf"), None
        for _ in range(REPEATS):
            result = ensemble(module, "rk4", client=client, **kwargs)
            best = min(best, result.wall_time)
    chunks = -(-len(k) // chunk_size(len(k), int(T_END / H_STEP), 2))
    return best, chunks, np.array_equal(result.q, local.q, equal_nan=True)


def run_ensemble_bench(report_path, models_dir="models", quick=False):
    """Measure and write the report; returns {name: number}."""
    import numba

    from ..codegen import generate_model
    from ..run.loader import import_generated
    M, subset = (1_000, 20) if quick else (10_000, 100)
    with tempfile.TemporaryDirectory() as tmp:
        result = generate_model(Path(models_dir) / "cart_pendulum.py", tmp, methods=["rk4"])
        module = import_generated(result.path)
        q0, v0, k = _members(M)
        threads = sorted({1, min(2, numba.config.NUMBA_NUM_THREADS)})
        timed, split = _time_ensembles(module, q0, v0, k, threads)
        per_member, sim_cores, equal = _time_simulate_loop(
            module, q0[:subset], v0[:subset], k[:subset], timed[1][2])
        n_dask = min(M, 2_000)
        dask = _time_dask(module, q0[:n_dask], v0[:n_dask], k[:n_dask],
                          _subset_result(timed[1][2], n_dask))
    one = timed[1][0]
    two = timed[threads[-1]][0]
    same = all(np.array_equal(timed[1][2].q, r.q, equal_nan=True) for _, _, r in timed.values())
    numbers = dict(members=M, rate_1=M / one, rate_2=M / two, ratio=one / two,
                   cores_1=timed[1][1], cores_2=timed[threads[-1]][1],
                   work_per_cpu_ratio=(one / two) * (timed[1][1] / timed[threads[-1]][1]),
                   cores_simulate=sim_cores, simulate_per_member=per_member,
                   simulate_rate=1.0 / per_member)
    lines = [
        "# Ensemble throughput (cart pendulum, rk4)", "",
        f"Members: {M}, each T = {T_END:g} with h = {H_STEP:g} ({int(T_END / H_STEP)} steps), "
        f"save_every = {SAVE_EVERY}; members differ in q0, v0 and k. Best of {REPEATS} runs. "
        f"Machine: {os.cpu_count()} cores, load average {os.getloadavg()[0]:.2f} at the end "
        f"(shared: other processes may run).", "",
        "| run | wall (s) | members / s | steps / s | cores obtained (CPU s / wall s) | "
        "members per CPU second |", "|---|---|---|---|---|---|",
    ]
    steps = M * int(T_END / H_STEP)
    for t, (sec, cores, _) in timed.items():
        lines.append(f"| ensemble, {t} thread{'s' if t > 1 else ''} | {sec:.3f} | "
                     f"{M / sec:,.0f} | {steps / sec:.3g} | {cores:.2f} | "
                     f"{M / sec / cores:,.0f} |")
    lines.append(f"| Python loop of simulate ({subset} members) | {per_member * M:.3f} "
                 f"(extrapolated) | {1 / per_member:,.0f} | "
                 f"{int(T_END / H_STEP) / per_member:.3g} | {sim_cores:.2f} | "
                 f"{1 / per_member / sim_cores:,.0f} |")
    c1, c2 = timed[1][1], timed[threads[-1]][1]
    work = (one / two) * (c1 / c2)
    lines += ["", f"2 threads / 1 thread (wall): **{one / two:.2f}x** (goal >= 1.8x). The runs "
              f"obtained {c1:.2f} and {c2:.2f} cores (CPU seconds of all threads / wall "
              f"seconds): where the 2-thread run gets fewer than 2 cores, other processes hold "
              f"them and the wall ratio measures the load, not the code. Work per CPU second, "
              f"2 threads / 1 thread: {work:.2f} (1.00 = no parallel overhead); on 2 free cores "
              f"that predicts {2 * work:.2f}x (a prediction, not a measurement).",
              f"CPU seconds per thread (threads above 0.05 s) of the best runs: "
              + "; ".join(f"{t} thread{'s' if t > 1 else ''}: "
                          + ", ".join(f"{x:.2f}" for x in split.get(t, []))
                          for t in threads) + ".",
              f"Ensemble (2 threads) / simulate loop: {per_member * M / two:.1f}x; simulate "
              f"costs {per_member * 1e3:.3f} ms per member.",
              f"1- and 2-thread results identical: {same}. The {subset} simulate runs equal "
              f"their ensemble members bitwise: {equal}."]
    if dask is None:
        lines.append("Dask: not installed (pip install 'dask[distributed]'), not measured.")
    else:
        wall, chunks, same_dask = dask
        local_2 = two * n_dask / M
        numbers.update(dask_wall=wall, dask_chunks=chunks)
        lines.append(f"Dask LocalCluster (2 worker processes, 1 thread each), {n_dask} members "
                     f"in {chunks} chunks: {wall:.3f} s against {local_2:.3f} s for the same "
                     f"members in the local 2-thread run (scaled from it): "
                     f"{(wall - local_2) / chunks * 1e3:.1f} ms per chunk more; arrays equal "
                     f"to the local run: {same_dask}.")
    write_report(report_path, lines)
    print("\n".join(lines))
    return numbers
