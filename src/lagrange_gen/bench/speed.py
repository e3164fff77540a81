"""`lagrange-gen bench speed`: the rows of the speed issue measured side by side in one run.

1. Cart pendulum, T = 10 from q0 = (0.1, 1.0): wall time to final-state error 1e-8 (the sweeps
   and the log-log interpolation of bench/precision.py) of our fastest method, dop853 included,
   against PyDy (cython right-hand side when it compiles) + scipy DOP853.
2. Cart pendulum, ns per step of every method that has a closed-form hand-written numba loop
   (bench/steppers.py) against that loop.
3. 16-link chain (models/n_link_pendulum.py, n = 16): ns per step of symplectic_euler, verlet
   and rk4 against MuJoCo's Euler and RK4 on the same chain (bench/mujoco_chain.py).
4. First simulate of a model just written: a new process with a fresh NUMBA_CACHE_DIR and
   LAGRANGE_GEN_PORTABLE_DIR that generates the model into a fresh directory and simulates a few
   steps (seconds beyond the interpreter's imports, and how much of it numba spends compiling
   the kernels and the stepper); then a new process to its first step with everything cached.
5. The cost of one call: the whole lg.simulate call as a user makes it against its jitted run,
   warm, with the stages around the run (call_breakdown); and dop853's whole call at error 1e-8
   against PyDy + scipy DOP853's whole solve_ivp call.

Ratios inside one run, not absolute times: the machine is shared. A peer that is not installed
is named in the report and its rows are left unmeasured.
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
import tempfile
from dataclasses import replace
from pathlib import Path

import numpy as np

from . import common, mujoco_chain, peers, precision
from ..analysis import reference as ref
from ..analysis import runs
from .steppers import HAND_CLOSED_FORM, measure_new_process, measure_step_times
from ..steppers.core import registry

CASE = precision.Case("cart_pendulum", (0.1, 1.0), (0.0, 0.0), 10.0, 100, 100)
CHAIN_N, CHAIN_H = 16, 1e-3
CHAIN_METHODS = ("symplectic_euler", "verlet", "rk4")
#: (label, model stem, build options, method, q0, goal seconds) of the cold-cache rows
COLD = (("cart pendulum, midpoint", "cart_pendulum", {}, "midpoint", [0.1, 1.0], 3.0),
        ("cart pendulum, verlet", "cart_pendulum", {}, "verlet", [0.1, 1.0], 3.0),
        ("cart pendulum, rk4", "cart_pendulum", {}, "rk4", [0.1, 1.0], 3.0),
        ("Cartesian pendulum, rattle", "cartesian_pendulum", {}, "rattle",
         [math.sin(0.5), -math.cos(0.5)], 5.0),
        ("10-link chain, verlet", "n_link_pendulum", {"n": 10}, "verlet",
         list(0.3 * np.sin(np.arange(1, 11))), 10.0))


def measure_precision(models_dir, gen_dir, quick, progress):
    """Seconds to final error 1e-8 per method: {"ours": {method: s or None}, "peers": {name:
    s or None}, "pydy": generator name or None}."""
    settings = replace(precision.QUICK if quick else precision.FULL, floor=common.TARGET / 10)
    mod = runs.load_module(models_dir, CASE.stem, gen_dir)
    p = runs.params_of(mod)
    reference = precision.reference_for_case(mod, CASE, p, settings)
    ours, dop853_points = {}, []
    for method in precision.methods_for_case(CASE, None):
        sweep = precision.sweep_adaptive if registry.spec(method).adaptive else \
            precision.sweep_ours
        points = sweep(mod, method, CASE, p, reference, settings, progress)
        ours[method] = common.time_at(points)
        if registry.spec(method).adaptive:      # dop853: the case has no contacts
            dop853_points = points
    found = {"scipy DOP853 on our right-hand side": ref.ode_rhs(mod, p)}
    pydy = peers.pydy_rhs(Path(models_dir) / f"{CASE.stem}.py", mod.PARAMS, p)
    if pydy is not None:
        found["PyDy + scipy DOP853"] = pydy[0]
    peer_points = {name: precision.sweep_peer(
        name, f, None, "DOP853", settings.dop_rtols, mod, CASE, p, reference, settings, progress)
        for name, f in found.items()}
    peer_times = {name: common.time_at(points) for name, points in peer_points.items()}
    whole = whole_call_at_target(mod, p, dop853_points, peer_points.get("PyDy + scipy DOP853"),
                                 repeats=5 if quick else 21)
    return {"ours": ours, "peers": peer_times, "pydy": pydy and pydy[2], "whole": whole}


def _first_at_target(points):
    """The first point of a sweep (coarse to fine) whose final error is at or below
    common.TARGET, or None."""
    return next((pt for pt in points or () if not pt.failed and pt.final <= common.TARGET), None)


def whole_call_at_target(mod, p, dop853_points, pydy_points, repeats):
    """The whole ``lg.simulate`` call as a user makes it (checks, set-up, the jitted run, the
    Trajectory) for dop853 at the first rtol of its sweep that reaches common.TARGET, median
    seconds over ``repeats`` calls, beside its jitted run alone (Trajectory.wall_time) and
    PyDy + scipy DOP853's whole solve_ivp call at its first rtol that reaches the target (the
    sweep's best of repeats; None when PyDy is not installed). Returns a dict."""
    import statistics
    import time
    from ..run.simulate import simulate
    ours = _first_at_target(dop853_points)
    if ours is None:
        return None
    t_grid = np.linspace(0.0, CASE.t_end, CASE.samples + 1)
    calls, runs_only = [], []
    for _ in range(repeats):
        start = time.perf_counter()
        traj = simulate(mod, "dop853", CASE.q0, CASE.v0, t_end=CASE.t_end, params=p,
                        t_eval=t_grid, rtol=ours.param, atol=ours.param / 100)
        calls.append(time.perf_counter() - start)
        runs_only.append(traj.wall_time)
    theirs = _first_at_target(pydy_points)
    return {"rtol": ours.param, "final": ours.final, "call": statistics.median(calls),
            "run": statistics.median(runs_only),
            "pydy": None if theirs is None else theirs.wall,
            "pydy_rtol": None if theirs is None else theirs.param,
            "pydy_final": None if theirs is None else theirs.final}


#: One warm call per row of the per-call breakdown: (label, method, simulate keywords).
CALLS = (("midpoint, 1 step", "midpoint", {"t_end": 1e-3, "h": 1e-3}),
         ("rk4, 1000 steps", "rk4", {"t_end": 1.0, "h": 1e-3}),
         ("dop853, t_end = 1e-3", "dop853", {"t_end": 1e-3}))


def call_breakdown(mod, calls=2000):
    """Per CALLS row: median microseconds over ``calls`` warm calls of the whole lg.simulate
    call, of the stepping (Trajectory.wall_time: the jitted run and its chunk loop) and of the
    phases around it, timed by wrapping the functions simulate calls (run/simulate.py's and
    run/run_result.py's names, restored afterwards): the output buffers (allocate), the driver
    less the stepping (glue choice, the compile notice), the Trajectory less the energy check,
    the energy check, the inputs and outputs (attach_inputs_outputs), and the checks and set-up
    (the whole call less all of these: simulate's own checks, the method's plan, parameters).
    Each phase is the median over the calls of its time in a call. The wrappers cost about a
    microsecond each, so the whole call, the stepping and the cost beyond it are timed first
    in calls without them; the phases come from a second pass of as many wrapped calls."""
    import statistics
    import time
    from ..run import run_result
    from ..run import simulate as sim
    wrapped = ((sim, "allocate", "buffers"), (sim, "integrate_fixed", "driver"),
               (sim, "integrate_adaptive", "driver"), (sim, "fixed_step_trajectory", "trajectory"),
               (sim, "adaptive_trajectory", "trajectory"), (run_result, "energy_warning", "energy"),
               (sim, "attach_inputs_outputs", "io"))
    spent, saved = {}, []

    def timed(phase, fn):
        def wrapper(*args, **kwargs):
            start = time.perf_counter()
            try:
                return fn(*args, **kwargs)
            finally:
                spent[phase] = spent.get(phase, 0.0) + time.perf_counter() - start
        return wrapper

    unwrapped = {}
    for label, method, kwargs in CALLS:
        sim.simulate(mod, method, CASE.q0, CASE.v0, **kwargs)              # compile or load
        whole, stepping = [], []
        for _ in range(calls):
            start = time.perf_counter()
            traj = sim.simulate(mod, method, CASE.q0, CASE.v0, **kwargs)
            whole.append(time.perf_counter() - start)
            stepping.append(traj.wall_time)
        unwrapped[label] = {"whole": whole, "stepping": stepping,
                            "beyond": [a - b for a, b in zip(whole, stepping)]}
    rows = []
    try:
        for owner, name, phase in wrapped:
            saved.append((owner, name, getattr(owner, name)))
            setattr(owner, name, timed(phase, getattr(owner, name)))
        for label, method, kwargs in CALLS:
            per_call = {k: [] for k in ("whole", "stepping", "beyond", "checks", "buffers",
                                        "driver", "trajectory", "energy", "io")}
            for _ in range(calls):
                spent.clear()
                start = time.perf_counter()
                traj = sim.simulate(mod, method, CASE.q0, CASE.v0, **kwargs)
                whole = time.perf_counter() - start
                phases = {k: spent.get(k, 0.0) for k in ("buffers", "driver", "trajectory",
                                                         "energy", "io")}
                phases["driver"] -= traj.wall_time
                phases["trajectory"] -= phases["energy"]
                around = sum(phases.values())
                phases.update(whole=whole, stepping=traj.wall_time,
                              beyond=whole - traj.wall_time,
                              checks=whole - traj.wall_time - around)
                for k, value in phases.items():
                    per_call[k].append(value)
            per_call.update(unwrapped[label])
            rows.append({"label": label, "jit": traj.jit,
                         **{k: 1e6 * statistics.median(v) for k, v in per_call.items()}})
    finally:
        for owner, name, fn in reversed(saved):
            setattr(owner, name, fn)
    return rows


def portable_step_ns(mod, method, steps, repeats):
    """ns per step of the portable glue (lagrange_gen.jit.portable) of ``method`` on ``mod``, timed
    as bench/steppers.py times the module's own run_<method>."""
    from ..jit import portable
    from .steppers import best_of, library_runner
    go = library_runner(mod, method, steps, portable.runner(mod, method))
    go()                                                  # compile or load
    return best_of(go, repeats)[0] / steps * 1e9


def chain_dir():
    """Where bench speed writes the 16-link chain's module: beside the portable glue (kept, so
    numba's cache of it serves the next run), not in the repository's generated/, which holds
    each model file's default build (writing there would leave generated/n_link_pendulum_16.py
    untracked after every run)."""
    from ..jit import portable
    return portable.portable_dir().parent / "bench"


def measure_chain(models_dir, gen_dir, quick):
    """ns per step on the 16-link chain: {"ours": {method: ns}, "mujoco": {integrator: {c_loop,
    python_loop}} or None, "equivalence": max abs state difference of the two rk4 runs}."""
    from ..run.loader import load
    from ..run.simulate import simulate
    mod = load(Path(models_dir) / "n_link_pendulum.py", out_dir=gen_dir,
               methods=list(CHAIN_METHODS), options={"n": CHAIN_N})
    th0, v0 = 0.3 * np.sin(np.arange(1, CHAIN_N + 1)), np.zeros(CHAIN_N)
    steps, repeats = (5_000, 2) if quick else (20_000, 3)
    ours, portable = {}, {}
    for method in CHAIN_METHODS:
        walls = [simulate(mod, method, th0, v0, t_end=steps * CHAIN_H, h=CHAIN_H,
                          save_every=steps).wall_time for _ in range(repeats)]
        ours[method] = 1e9 * min(walls) / steps
        walls = [simulate(mod, method, th0, v0, t_end=steps * CHAIN_H, h=CHAIN_H,
                          save_every=steps, jit="portable").wall_time for _ in range(repeats)]
        portable[method] = 1e9 * min(walls) / steps
    if not mujoco_chain.available():
        return {"ours": ours, "portable": portable, "mujoco": None, "equivalence": None}
    params = runs.params_of(mod)                          # (m, l, g)
    theirs = {name: mujoco_chain.ns_per_step(CHAIN_N, CHAIN_H, name, params, th0, v0, steps,
                                             repeats) for name in ("Euler", "RK4")}
    return {"ours": ours, "portable": portable, "mujoco": theirs,
            "equivalence": mujoco_chain.equivalence(mod, params, th0, CHAIN_H)}


_COLD_CHILD = r"""
import json, sys, time
t0 = time.perf_counter()
import numba, numpy  # noqa: F401
from lagrange_gen.jit.compile_notice import time_outermost_compiles
from lagrange_gen.run.loader import load
from lagrange_gen.run.simulate import simulate
t1 = time.perf_counter()
# where the compile time goes: numba's outermost compiles, by what they compile
seconds = time_outermost_compiles(lambda name: (
    "kernels" if name.startswith("lagrange_gen_generated") else "stepper"
    if name.startswith(("lagrange_gen_portable", "lagrange_gen.steppers")) else "other"))
path, out_dir, method, options, q0, jit = sys.argv[1], sys.argv[2], sys.argv[3], \
    json.loads(sys.argv[4]), json.loads(sys.argv[5]), sys.argv[6]
mod = load(path, out_dir=out_dir, methods=[method], options=options)
t2 = time.perf_counter()
traj = simulate(mod, method, q0, None, t_end=0.01, h=1e-3, jit=jit)
t3 = time.perf_counter()
print(json.dumps({"imports": t1 - t0, "generate": t2 - t1, "first_simulate": t3 - t2,
                  "path": mod.__file__, "jit": traj.jit,
                  "compiles": {"kernels": 0.0, "stepper": 0.0, "other": 0.0} | seconds}))
"""


#: The model that runs first in the "library cached" variant of each cold row: another model
#: of the same kind (constrained for rattle), so that only the stepper library's own cached
#: functions (linalg, status checks, ...) are reused, nothing of the model measured.
WARMUP_STEM = {"rattle": ("cartesian_double_pendulum", [0.6, -0.8, 1.2, -1.6])}
WARMUP_DEFAULT = ("double_pendulum", [0.1, 0.2])


def _cold_child(models_dir, stem, options, method, q0, out_dir, cache, jit="auto"):
    """Run _COLD_CHILD in a new process with NUMBA_CACHE_DIR=cache (numba's cache of the
    portable glue included: it lives there too) and LAGRANGE_GEN_PORTABLE_DIR=cache-portable
    (the portable glue's sources), and simulate(jit=jit); its timings (dict)."""
    from ..jit.first_run import BACKGROUND_ENV
    from ..jit.portable import DIR_ENV
    # no background compile (jit.first_run): it would load the machine under the next rows
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache),
               **{DIR_ENV: f"{cache}-portable", BACKGROUND_ENV: "0"})
    done = subprocess.run([sys.executable, "-c", _COLD_CHILD, str(Path(models_dir) / f"{stem}.py"),
                           str(out_dir), method, json.dumps(options), json.dumps(q0), jit],
                          env=env, capture_output=True, text=True)
    if done.returncode != 0:
        last = (done.stderr.strip().splitlines() or ["no output"])[-1]
        raise RuntimeError(f"bench speed: cold child for {stem} ({method}) failed: {last}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def measure_cold(models_dir, work):
    """Per COLD row: {label, method, goal, path, cache (the fully cold run's numba cache),
    generate, first_simulate, total, jit, library_cached, library_jit, specialized}, seconds
    beyond the interpreter's imports of a new process that generates the model into a fresh
    directory and simulates a few steps with the default simulate(jit="auto"):

    - library_cached: a model just written, in a numba cache where another model
      (WARMUP_STEM) already ran the method, so the portable stepper is cached and nothing of
      this model is: what a user pays for every new model but the first after an install;
    - total: everything cold (fresh NUMBA_CACHE_DIR): the first model after an install also
      compiles the portable stepper;
    - specialized: everything cold with jit="specialized" (the model's own stepper compiled,
      as before the portable glue existed)."""
    rows = []
    for i, (label, stem, options, method, q0, goal) in enumerate(COLD):
        cache = Path(work) / f"cache{i}"
        cold = _cold_child(models_dir, stem, options, method, q0, Path(work) / f"gen{i}", cache)
        warm_cache = Path(work) / f"libcache{i}"
        warm_stem, warm_q0 = WARMUP_STEM.get(method, WARMUP_DEFAULT)
        # (jit="portable": compiles the portable stepper, which "auto" would only interpret)
        _cold_child(models_dir, warm_stem, {}, method, warm_q0, Path(work) / f"wgen{i}", warm_cache,
                    jit="portable")
        lib = _cold_child(models_dir, stem, options, method, q0, Path(work) / f"lgen{i}", warm_cache)
        own = _cold_child(models_dir, stem, options, method, q0, Path(work) / f"sgen{i}",
                          Path(work) / f"scache{i}", jit="specialized")
        rows.append({"label": label, "method": method, "goal": goal, "cache": cache, **cold,
                     "library_compiles": lib["compiles"],
                     "total": cold["generate"] + cold["first_simulate"],
                     "library_cached": lib["generate"] + lib["first_simulate"],
                     "library_generate": lib["generate"], "library_jit": lib["jit"],
                     "specialized": own["generate"] + own["first_simulate"]})
        print(f"cold {label}: model just written {rows[-1]['library_cached']:.1f} s "
              f"({lib['jit']}), fully cold {rows[-1]['total']:.1f} s, specialized fully cold "
              f"{rows[-1]['specialized']:.1f} s", flush=True)
    return rows


def run_speed_bench(models_dir="models", gen_dir="generated", reports_dir="reports",
                    quick=False):
    """Measure every row, write reports_dir/speed.md; returns {"results", "report"}."""
    from .speed_report import markdown
    common.precompile(models_dir, gen_dir, [(CASE.stem, {})])
    mod = runs.load_module(models_dir, CASE.stem, gen_dir)
    results = {"quick": quick, "mujoco": mujoco_chain.available(), "case": CASE,
               "chain_n": CHAIN_N}
    with tempfile.TemporaryDirectory() as tmp:
        results["cold"] = measure_cold(models_dir, tmp)
        # the warm start reuses the cache the cold rk4 row filled
        rk4 = {r["method"]: r for r in results["cold"]}["rk4"]
        results["warm"] = measure_new_process(rk4["path"], "rk4", rk4["cache"])
    bar = common.Progress(0, "speed", enabled=False)
    results["precision"] = measure_precision(models_dir, gen_dir, quick, bar)
    results["calls"] = call_breakdown(mod, calls=300 if quick else 2000)
    steps, repeats = (20_000, 2) if quick else (100_000, 5)
    results["steps"] = [r for r in measure_step_times(mod, steps, repeats)
                        if r["method"] in HAND_CLOSED_FORM]
    for row in results["steps"]:
        row["portable_ns"] = portable_step_ns(mod, row["method"], steps, repeats)
    results["chain"] = measure_chain(models_dir, chain_dir(), quick)
    lines = markdown(results)
    path = common.write_report(Path(reports_dir) / "speed.md", lines)
    return {"results": results, "report": path}
