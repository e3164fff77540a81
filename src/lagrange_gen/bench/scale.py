"""`lagrange-gen bench scale`: cost of the pipeline against the number of links of a pendulum.

For the planar n-link pendulum (models/n_link_pendulum.py), n = 1, 2, 4, 8, 12, 16, 20, it
measures derive and emit time, generated size (lines; operations of the CSE'd kernels by sympy
count_ops), first numba compile of the kernels and of the verlet/midpoint glue, the cached
import plus first step of a second process, and ns per forward-dynamics evaluation and per
verlet/midpoint step inside jitted loops. In the same run it times sympy.physics.mechanics
LagrangesMethod (form_lagranges_equations, mass matrix, forcing) on the same chain until one case
exceeds a per-case budget. PyDy and MuJoCo are compared only when installed.

Modules are generated with ``--methods verlet,midpoint`` (the two steppers measured: a scene
gets only what it needs); at one size the default all-methods module's kernel compile is
measured too. Every compile measurement runs in a fresh process with its own NUMBA_CACHE_DIR.
"""

from __future__ import annotations

import importlib.util
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

SIZES = (1, 2, 4, 8, 12, 16, 20, 24, 32)
QUICK_SIZES = (1, 2, 4)
METHODS = ("verlet", "midpoint")
BUDGET_S, QUICK_BUDGET_S = 150.0, 20.0       # per LagrangesMethod case
ALL_METHODS_AT = 16                           # size at which the all-methods module is compiled too


def measure_generation(model_file, n, out_dir, methods=METHODS):
    """Generate the n-link module into out_dir; dict of derive/emit seconds, lines, ops, path."""
    import sympy as sp
    from ..codegen.generate import generate_parts
    from ..codegen.write import write_if_changed
    from ..model.model_file import load_model
    model = load_model(model_file, n=n)
    parts = generate_parts(model, out_dir, methods=list(methods) if methods else None)
    write_if_changed(parts.target, parts.text)
    ops = sum(sp.count_ops(e) for t in parts.texts for e in t.cse_exprs)
    return {"derive": parts.seconds["derive"], "emit": parts.seconds["emit"], "path": str(parts.target),
            "lines": parts.text.count("\n"), "ops": int(ops), "kernels": [t.name for t in parts.texts]}


def _run_child(args, cache_dir, timeout=None):
    """Run this module as a child (``--child ...``); its last stdout line is JSON."""
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache_dir))
    out = subprocess.run([sys.executable, "-m", "lagrange_gen.bench.scale", "--child", *map(str, args)],
                         env=env, capture_output=True, text=True, timeout=timeout)
    if out.returncode != 0:
        last = (out.stderr.strip().splitlines() or ["no output"])[-1]
        raise RuntimeError(f"scale bench child {args[0]} failed: {last}")
    return json.loads(out.stdout.strip().splitlines()[-1])


def measure_case(model_file, n, work, attempts=2):
    """All measurements of our pipeline for one n (a dict of seconds, ns and sizes).

    Other developers edit the generator's sources in the same tree; a module that went stale
    between generation and a child's import (StaleModuleError) is generated and measured again.
    """
    for attempt in range(attempts):
        row = {"n": n, **measure_generation(model_file, n, work / f"gen{n}_{attempt}")}
        cache = work / f"cache{n}_{attempt}"
        try:
            row.update(_run_child(["cold", row["path"]], cache))
            row.update(_run_child(["warm", row["path"]], cache))
            return row
        except RuntimeError as exc:
            if "StaleModuleError" not in str(exc) or attempt == attempts - 1:
                raise
            print(f"n={n}: sources changed during the measurement, measuring again", flush=True)
    return row


def measure_all_methods(model_file, n, work):
    """Kernel first compile of the default (all methods) module: every kernel emitted."""
    gen = measure_generation(model_file, n, work / f"all{n}", methods=None)
    cold = _run_child(["kernels", gen["path"]], work / f"cache_all{n}")
    return {"n": n, "derive": gen["derive"], "emit": gen["emit"], "lines": gen["lines"], "ops": gen["ops"],
            "kernels_compile": cold["kernels_compile"], "ns_forward": cold["ns_forward"],
            "count": len(gen["kernels"])}


def measure_lagranges_method(n, budget):
    """Seconds of sympy LagrangesMethod on the n-link chain, or None past the budget."""
    try:
        return _run_child(["lm", n], tempfile.gettempdir(), timeout=budget)["seconds"]
    except subprocess.TimeoutExpired:
        return None


def installed(name):
    return importlib.util.find_spec(name) is not None


def run_scale_bench(models_dir="models", reports_dir="reports", quick=False):
    """Measure every size, write reports/scale.md and reports/scale.png; returns the rows.

    LagrangesMethod runs right after our measurements of the same n, so that both see the
    same load on a shared machine; once a case exceeds the budget, larger n are skipped.
    """
    from .scale_report import write_report
    model_file = Path(models_dir) / "n_link_pendulum.py"
    sizes = QUICK_SIZES if quick else SIZES
    budget = QUICK_BUDGET_S if quick else BUDGET_S
    rows, lm, exceeded = [], {}, None
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        for n in sizes:
            rows.append(measure_case(model_file, n, work))
            lm[n] = measure_lagranges_method(n, budget) if exceeded is None else None
            if exceeded is None and lm[n] is None:
                exceeded = n
            _print_row(rows[-1], lm[n], budget)
        extra = measure_all_methods(model_file, ALL_METHODS_AT, work) if ALL_METHODS_AT in sizes else None
    peers = {name: installed(name) for name in ("pydy", "mujoco")}
    write_report(Path(reports_dir), rows, lm, exceeded, budget, extra, peers, METHODS)
    return rows


def _print_row(r, lm, budget):
    ref = f"{lm:.2f} s" if lm is not None else f"> {budget:.0f} s or skipped"
    print(f"n={r['n']}: derive {r['derive']:.2f} s, emit {r['emit']:.2f} s, kernels "
          f"{r['kernels_compile']:.2f} s, glue {r['glue_compile']:.2f} s, cached first step "
          f"{r['cached_first_step']:.3f} s; LagrangesMethod {ref}", flush=True)


# ---------------------------------------------------------------- child processes


def _child_imports():
    start = time.perf_counter()
    import numba  # noqa: F401
    import numpy  # noqa: F401
    from ..run.loader import compile_all, import_generated  # noqa: F401
    from ..run.simulate import simulate  # noqa: F401
    return time.perf_counter() - start


def _state(n):
    import numpy as np
    return 0.3 * np.sin(np.arange(1, n + 1)), np.zeros(n)


def _child_cold(path):
    """First compile in a fresh cache: kernels, then each method's glue, then the loops."""
    out = {"imports": _child_imports()}
    from ..run.loader import compile_all, import_generated
    start = time.perf_counter()
    mod = import_generated(path)
    out["module_import"] = time.perf_counter() - start
    start = time.perf_counter()
    compile_all(mod)
    out["kernels_compile"] = time.perf_counter() - start
    out["glue_compile"] = 0.0
    for method in METHODS:
        compile_s, ns = _step_cost(mod, method)
        out["glue_compile"] += compile_s
        out[f"ns_{method}"] = ns
    out["ns_forward"] = _forward_cost(mod)
    return out


def _step_cost(mod, method, h=1e-3, target_s=0.3):
    """(glue compile seconds, ns per step inside the jitted loop) of one method."""
    from ..run.simulate import simulate
    q0, v0 = _state(mod.N_COORDS)
    probe = simulate(mod, method, q0, v0, t_end=20 * h, h=h, save_every=20)
    steps = int(min(200_000, max(50, target_s / max(probe.wall_time / 20, 1e-9))))
    run = simulate(mod, method, q0, v0, t_end=steps * h, h=h, save_every=steps)
    return probe.compile_time, 1e9 * run.wall_time / steps


def _forward_cost(mod, target_s=0.3):
    """ns per forward_dynamics call inside a jitted loop (min of 3 repeats)."""
    import numpy as np
    from numba import njit
    fd = mod.forward_dynamics

    @njit
    def loop(q, v, p, H, a, reps):
        total = 0.0
        for _ in range(reps):
            fd(q, v, 0.0, p, H, a)
            total += a[0]
        return total

    n = mod.N_COORDS
    q, v = _state(n)
    v = v + 0.1
    H, a, p = np.empty((n, n)), np.empty(n), mod.DEFAULT_PARAMS.copy()
    loop(q, v, p, H, a, 1)
    start = time.perf_counter()
    loop(q, v, p, H, a, 100)
    reps = int(max(100, target_s / max((time.perf_counter() - start) / 100, 1e-9)))
    best = np.inf
    for _ in range(3):
        start = time.perf_counter()
        loop(q, v, p, H, a, reps)
        best = min(best, (time.perf_counter() - start) / reps)
    return 1e9 * best


def _child_warm(path):
    """A second process with a warm cache: import, load the kernels, take one verlet step."""
    out = {"warm_imports": _child_imports()}
    from ..run.loader import compile_all, import_generated
    from ..run.simulate import simulate
    start = time.perf_counter()
    mod = import_generated(path)
    q0, v0 = _state(mod.N_COORDS)
    simulate(mod, "verlet", q0, v0, t_end=1e-3, h=1e-3)
    out["cached_first_step"] = time.perf_counter() - start
    start = time.perf_counter()
    compile_all(mod)
    out["cached_kernels"] = time.perf_counter() - start
    return out


def _child_kernels(path):
    """First compile of the kernels only, and the forward-dynamics cost of that module."""
    _child_imports()
    from ..run.loader import compile_all, import_generated
    start = time.perf_counter()
    mod = import_generated(path)
    compile_all(mod)
    return {"kernels_compile": time.perf_counter() - start, "ns_forward": _forward_cost(mod)}


def _child_lm(n):
    from .pipeline import measure_sympy
    return {"seconds": measure_sympy(f"n_link_pendulum_{int(n)}")}


def _child_main(argv):
    phase, arg = argv[0], argv[1]
    handlers = {"cold": _child_cold, "warm": _child_warm, "kernels": _child_kernels, "lm": _child_lm}
    print(json.dumps(handlers[phase](arg)))


if __name__ == "__main__" and sys.argv[1:2] == ["--child"]:
    _child_main(sys.argv[2:])
