"""Stepper speed: ns per step of every method on the cart pendulum, against hand-written numba
loops of the same methods measured in the same run, and the time a new process needs to its
first step when numba's cache is warm.

Two references per method where one exists:
* "hand, closed form" (bench/hand_loops.py): what a person would write for this one model,
  the equations of the cart pendulum typed in by hand and 2 x 2 solves by Cramer's rule (no
  generality, no checks);
* "hand, generated kernels": a plain loop over the generated forward_dynamics, i.e. the same
  kernels and the same Cholesky solve as the library, without the library's stepping machinery.
The implicit references (symplectic Euler, Verlet) use the same Newton stopping rule as the
library, so both do the same number of iterations. Every reference must end in the library's
final state (to round-off) or the bench refuses to report it.

Run: ``python -m lagrange_gen.bench.steppers [--quick]`` (writes reports/steppers.md), or
``run_steppers_bench()`` from Python.
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from ..jit.cache import njit

from ..analysis.runs import unconstrained_methods
from .hand_loops import HAND_CLOSED_FORM, NEWTON_HAND, TOL
from ..steppers.core import registry
from ..steppers.core.layout import N_STATS, events_size, last_size
from ..steppers.core.method_spec import make_settings

ROOT = Path(__file__).resolve().parents[3]
Q0, V0, H_STEP = (0.1, 0.5), (0.0, 0.0), 1e-3


# ---------------------------------------------------------------- hand-written, generated kernels

def _kernel_loops(mod):
    """Plain loops over the module's forward_dynamics (explicit Euler and RK4)."""
    fd = mod.forward_dynamics

    @njit
    def euler(q0, v0, h, n, p):
        q, v = q0.copy(), v0.copy()
        nq = q.shape[0]
        a, H = np.empty(nq), np.empty((nq, nq))
        for i in range(n):
            if fd(q, v, i * h, p, H, a) != 0:
                break
            for j in range(nq):
                q[j] += h * v[j]
                v[j] += h * a[j]
        return np.concatenate((q, v))

    @njit
    def rk4(q0, v0, h, n, p):
        q, v = q0.copy(), v0.copy()
        nq = q.shape[0]
        H = np.empty((nq, nq))
        a1, a2, a3, a4 = np.empty(nq), np.empty(nq), np.empty(nq), np.empty(nq)
        qs, v2, v3, v4 = np.empty(nq), np.empty(nq), np.empty(nq), np.empty(nq)
        for i in range(n):
            t = i * h
            fd(q, v, t, p, H, a1)
            for j in range(nq):
                qs[j] = q[j] + 0.5 * h * v[j]
                v2[j] = v[j] + 0.5 * h * a1[j]
            fd(qs, v2, t + 0.5 * h, p, H, a2)
            for j in range(nq):
                qs[j] = q[j] + 0.5 * h * v2[j]
                v3[j] = v[j] + 0.5 * h * a2[j]
            fd(qs, v3, t + 0.5 * h, p, H, a3)
            for j in range(nq):
                qs[j] = q[j] + h * v3[j]
                v4[j] = v[j] + h * a3[j]
            fd(qs, v4, t + h, p, H, a4)
            for j in range(nq):
                q[j] += h / 6 * (v[j] + 2 * v2[j] + 2 * v3[j] + v4[j])
                v[j] += h / 6 * (a1[j] + 2 * a2[j] + 2 * a3[j] + a4[j])
        return np.concatenate((q, v))

    return {"explicit_euler": euler, "rk4": rk4}


# ---------------------------------------------------------------- measurement

def best_of(fn, repeats):
    best = math.inf
    for _ in range(repeats):
        start = time.perf_counter()
        result = fn()
        best = min(best, time.perf_counter() - start)
    return best, result


def library_runner(mod, method, n_steps, run=None):
    """A zero-argument call of ``run`` (default: the module's run_<method>; the portable glue's
    runner, lagrange_gen.jit.portable, takes the same arguments) for n_steps steps from (Q0, V0),
    returning (final state, Newton iterations per step)."""
    run = run or getattr(mod, f"run_{method}")
    n = mod.N_COORDS
    q0, v0 = np.array(Q0), np.array(V0)
    out = (np.empty(2), np.empty((2, n)), np.empty((2, n)), np.empty((2, N_STATS)),
           np.empty((2, 0)), np.empty(last_size(n, 0)), np.empty((0, events_size(n))))
    spec = registry.spec(method)
    settings = make_settings(spec, {"newton_tol": TOL} if "newton_tol" in spec.setting_names()
                             else {})

    def go():
        status, _, _ = run(q0, v0, 0.0, H_STEP, n_steps, n_steps, mod.DEFAULT_PARAMS, settings,
                           *out)
        if status != 0:
            raise RuntimeError(f"bench: {method} failed with status {status}")
        return np.concatenate((out[1][1], out[2][1])), out[3][1, 1] / n_steps
    return go


def measure_step_times(mod, n_steps=100_000, repeats=5):
    """Rows {method, ours_ns, iters, hand_ns, hand_kernels_ns, max_diff} for every method."""
    q0, v0, p = np.array(Q0), np.array(V0), mod.DEFAULT_PARAMS
    kernel_loops = _kernel_loops(mod)
    rows = []
    for method in unconstrained_methods():
        go = library_runner(mod, method, n_steps)
        go()                                                      # compile or load
        ours, (state, iters) = best_of(go, repeats)
        row = {"method": method, "ours_ns": ours / n_steps * 1e9, "iters": iters}
        refs = {}
        if method in HAND_CLOSED_FORM:
            fn = HAND_CLOSED_FORM[method]
            # the implicit references take the Newton tolerance
            args = (q0, v0, H_STEP, n_steps, p) + ((TOL,) if method in NEWTON_HAND else ())
            refs["hand_ns"] = lambda fn=fn, args=args: fn(*args)
        if method in kernel_loops:
            fn = kernel_loops[method]
            refs["hand_kernels_ns"] = lambda fn=fn: fn(q0, v0, H_STEP, n_steps, p)
        diffs = []
        for key, call in refs.items():
            call()
            elapsed, ref_state = best_of(call, repeats)
            diffs.append(float(np.abs(ref_state - state).max()))
            if diffs[-1] > 1e-8 * max(1.0, np.abs(state).max()):
                raise RuntimeError(f"bench: {key} reference of {method} disagrees with the "
                                   f"library by {diffs[-1]:.3g}; not the same method")
            row[key] = elapsed / n_steps * 1e9
        row["max_diff"] = max(diffs) if diffs else None
        rows.append(row)
    return rows


_CHILD = r"""
import json, sys, time
t0 = time.perf_counter()
import numpy as np
import numba  # noqa: F401
t1 = time.perf_counter()
from lagrange_gen.run.loader import import_generated
from lagrange_gen.steppers.core import registry
from lagrange_gen.steppers.core.layout import N_STATS, events_size, last_size
from lagrange_gen.steppers.core.method_spec import make_settings
mod = import_generated(sys.argv[1])
t2 = time.perf_counter()
run = getattr(mod, "run_" + sys.argv[2])
n = mod.N_COORDS
status, done, _ = run(np.array([0.1, 0.5]), np.zeros(n), 0.0, 1e-3, 1, 1, mod.DEFAULT_PARAMS,
                      make_settings(registry.spec(sys.argv[2]), {}), np.empty(2),
                      np.empty((2, n)), np.empty((2, n)), np.empty((2, N_STATS)),
                      np.empty((2, 0)), np.empty(last_size(n, 0)), np.empty((0, events_size(n))))
t3 = time.perf_counter()
print(json.dumps({"imports": t1 - t0, "module_import": t2 - t1, "first_step": t3 - t2,
                  "status": int(status), "hits": sum(run.stats.cache_hits.values()),
                  "misses": sum(run.stats.cache_misses.values())}))
"""


def measure_new_process(module_path, method, cache_dir):
    """Seconds for a new interpreter to its first step with a warm numba cache (the cache is
    warmed by a first child). Returns the warm child's timings plus its total wall time."""
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache_dir))

    def child():
        start = time.perf_counter()
        out = subprocess.run([sys.executable, "-c", _CHILD, str(module_path), method], env=env,
                             capture_output=True, text=True)
        wall = time.perf_counter() - start
        if out.returncode != 0:
            last = (out.stderr.strip().splitlines() or ["no output"])[-1]
            raise RuntimeError(f"bench child failed: {last}")
        data = json.loads(out.stdout.strip().splitlines()[-1])
        data["wall"] = wall
        return data

    cold = child()
    warm = child()
    if warm["misses"] or not warm["hits"]:
        raise RuntimeError(f"bench: run_{method} was recompiled in a new process: {warm}")
    warm["cold_wall"] = cold["wall"]
    return warm


def run_steppers_bench(report_path=ROOT / "reports" / "steppers.md",
                       model_file=ROOT / "models" / "cart_pendulum.py", quick=False):
    """Measure, write the markdown report, return the numbers."""
    from ..codegen import generate_model
    from ..run.loader import import_generated
    n_steps, repeats = (20_000, 2) if quick else (100_000, 5)
    with tempfile.TemporaryDirectory() as tmp:
        path = generate_model(model_file, Path(tmp) / "gen").path
        mod = import_generated(path)
        rows = measure_step_times(mod, n_steps, repeats)
        startup = {m: measure_new_process(path, m, Path(tmp) / "numba_cache")
                   for m in ("rk4", "midpoint")}
    report = _markdown(rows, startup, n_steps, mod.NAME)
    if report_path:
        Path(report_path).parent.mkdir(parents=True, exist_ok=True)
        Path(report_path).write_text(report)
    return {"steps": rows, "startup": startup, "report": report}


def _fmt(x, spec=".0f"):
    return "-" if x is None else format(x, spec)


def _markdown(rows, startup, n_steps, name):
    lines = [
        "# Stepper speed", "",
        f"`python -m lagrange_gen.bench.steppers`: {name}, h = {H_STEP:g}, {n_steps} steps from "
        f"q0 = {Q0}, v0 = {V0}; best of several runs, one process, ns per step.", "",
        "| method | library | Newton it./step | hand, closed form | ratio "
        "| hand, generated kernels | ratio |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        hand, kern = r.get("hand_ns"), r.get("hand_kernels_ns")
        lines.append(f"| {r['method']} | {r['ours_ns']:.0f} | {r['iters']:.2f} | {_fmt(hand)} | "
                     f"{_fmt(hand and r['ours_ns'] / hand, '.2f')} | {_fmt(kern)} | "
                     f"{_fmt(kern and r['ours_ns'] / kern, '.2f')} |")
    lines += ["", "Every reference ends in the library's final state to round-off (checked).", "",
              "## New process to its first step (warm numba cache)", "",
              "| method | total wall | interpreter + numpy/numba imports "
              "| generated module import | run_<method> load + first step "
              "| cold cache total wall |", "|---|---|---|---|---|---|"]
    for method, s in startup.items():
        lines.append(f"| {method} | {s['wall']:.2f} s | {s['imports']:.2f} s | "
                     f"{s['module_import']:.2f} s | {s['first_step']:.3f} s | "
                     f"{s['cold_wall']:.2f} s |")
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    result = run_steppers_bench(quick="--quick" in sys.argv)
    print(result["report"])
