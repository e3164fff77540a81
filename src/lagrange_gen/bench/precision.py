"""`lagrange-gen bench precision`: work-precision diagrams, our steppers against the peers.

For each model of the suite and each stepper, h = h0 / 2^k (k = 0, 1, ...) until the final error
reaches round-off, the run gets too long, or k_max; for each peer a sweep of tolerances. Every
run is compared with a DOP853 reference at rtol 1e-13 that a second solver has confirmed
(analysis.reference). Errors (max norm over q and v): the final state, the maximum over S sample
times, max |E - E0| over the samples and, for constrained models, max |Phi|. Time: integration
wall time, minimum over repeats, after a warm-up (simulate compiles or loads the glue before its
clock starts; the peers' right-hand sides are called once before timing).

Failed runs (blow-up, Newton divergence, solver failure) stay in the table and are drawn as
crosses at the top of the figure.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from . import common, peers
from ..analysis import reference as ref
from ..analysis import runs
from ..steppers.core import registry



@dataclass(frozen=True)
class Case:
    """One model of the suite: initial state, end time, n0 steps at k = 0 (h0 = t_end / n0) and
    the number of sample times S (a divisor of n0)."""

    stem: str
    q0: tuple
    v0: tuple
    t_end: float
    n0: int
    samples: int
    constrained: bool = False
    note: str = ""


def _fpu_start(omega=50.0):
    """HARD_CASES case 5: q1 = (1 - 1/omega)/sqrt 2, q2 = (1 + 1/omega)/sqrt 2, p2 = sqrt 2."""
    r = math.sqrt(2.0)
    return ((1 - 1 / omega) / r, (1 + 1 / omega) / r, 0, 0, 0, 0), (0, r, 0, 0, 0, 0)


CASES = (
    Case("cart_pendulum", (0.1, 0.5), (0.0, 0.0), 10.0, 100, 100),
    Case("double_pendulum", (0.5, 1.0), (0.0, 0.0), 10.0, 200, 100),
    Case("fpu", *_fpu_start(), 5.0, 250, 50, note="h0 omega = 1"),
    Case("cartesian_pendulum", (math.sin(0.5), -math.cos(0.5)), (0.0, 0.0), 10.0, 100, 100,
         constrained=True),
)


@dataclass(frozen=True)
class Settings:
    k_max: int
    repeats: int
    budget: float                 # stop a method's sweep after a run slower than this (s)
    dop_rtols: tuple
    radau_rtols: tuple
    second: str                   # second reference solver: "Radau" or "LSODA"
    floor: float = 1e-12          # stop refining once the final error is below this
    cases: tuple = field(default=CASES)


FULL = Settings(k_max=12, repeats=3, budget=2.0, second="Radau",
                dop_rtols=tuple(10.0 ** -k for k in range(3, 14)),
                radau_rtols=tuple(10.0 ** -k for k in range(3, 11)))
# quick: the headline model and the constrained one (each model costs numba compiles when cold)
QUICK = Settings(k_max=6, repeats=2, budget=0.2, second="LSODA",
                 dop_rtols=(1e-4, 1e-7, 1e-10), radau_rtols=(1e-4, 1e-7),
                 cases=tuple(c for c in CASES if c.stem in ("cart_pendulum",
                                                             "cartesian_pendulum")))


@dataclass
class Point:
    """One run: ``param`` is h (ours) or rtol (peers); errors are max norms (NaN if failed)."""

    method: str
    kind: str                     # "ours" or "peer"
    param: float
    wall: float
    final: float = math.nan
    traj_max: float = math.nan
    energy: float = math.nan
    phi: float = math.nan
    failed: str = ""


def _errors(point, mod, p, reference, t_grid, y_grid, y_end):
    """Fill the error fields of ``point`` from states y_grid (2n, S) at t_grid and y_end (2n,)."""
    n = mod.N_COORDS
    exact = reference.y_at(t_grid)
    point.final = float(np.max(np.abs(y_end - reference.y_end)))
    point.traj_max = float(np.max(np.abs(y_grid - exact)))
    e = np.array([mod.energy(np.ascontiguousarray(y[:n]), np.ascontiguousarray(y[n:]), t, p)
                  for t, y in zip(t_grid, y_grid.T)])
    point.energy = float(np.max(np.abs(e - e[0])))
    if mod.N_CONSTRAINTS:
        point.phi = float(np.max(ref.constraint_residual(mod, p, y_grid[:n].T)))
    return point


def sweep_ours(mod, method, case, p, reference, settings, progress):
    """h = h0 / 2^k for k = 0..k_max; stops once the final error is below settings.floor or a
    run takes longer than settings.budget. Returns [Point]."""
    points, t_grid = [], np.linspace(0.0, case.t_end, case.samples + 1)
    q0, v0 = np.array(case.q0, float), np.array(case.v0, float)
    for k in range(settings.k_max + 1):
        n_steps = case.n0 * 2**k
        h = case.t_end / n_steps
        run = runs.guarded_run(mod, method, q0, v0, h, case.t_end, p,
                               save_every=n_steps // case.samples, repeats=settings.repeats)
        progress.step(f"{case.stem} {method} h={h:.2g}")
        if not run.ok:
            points.append(Point(method, "ours", h, run.wall, failed=run.error))
            continue
        tr = run.traj
        y_grid = np.vstack((tr.q.T, tr.v.T))
        points.append(_errors(Point(method, "ours", h, run.wall), mod, p, reference, t_grid,
                              y_grid, y_grid[:, -1]))
        if points[-1].final < settings.floor or run.wall > settings.budget:
            progress.step(count=settings.k_max - k)      # the runs this sweep skips
            break
    return points


def sweep_adaptive(mod, method, case, p, reference, settings, progress):
    """An adaptive method of ours (dop853) over settings.dop_rtols (atol = rtol / 100), states
    at the sample times from its dense output; stops after a run slower than the budget or once
    the final error is below the floor. Point.param is the rtol. Returns [Point]."""
    points, t_grid = [], np.linspace(0.0, case.t_end, case.samples + 1)
    q0, v0 = np.array(case.q0, float), np.array(case.v0, float)
    rtols = settings.dop_rtols
    for i, rtol in enumerate(rtols):
        run = runs.guarded_run(mod, method, q0, v0, None, case.t_end, p,
                               repeats=settings.repeats, t_eval=t_grid, rtol=rtol,
                               atol=rtol / 100)
        progress.step(f"{case.stem} {method} rtol={rtol:.0e}")
        if not run.ok:
            points.append(Point(method, "ours", rtol, run.wall, failed=run.error))
            continue
        tr = run.traj
        y_grid = np.vstack((tr.q.T, tr.v.T))
        points.append(_errors(Point(method, "ours", rtol, run.wall), mod, p, reference, t_grid,
                              y_grid, y_grid[:, -1]))
        if points[-1].final < settings.floor or run.wall > settings.budget:
            progress.step(count=len(rtols) - 1 - i)
            break
    return points


def sweep_peer(name, f, jac, method, rtols, mod, case, p, reference, settings, progress):
    """One solve_ivp method over rtols on the right-hand side f; stops after a run slower than
    the budget. Returns [Point]."""
    t_grid = np.linspace(0.0, case.t_end, case.samples + 1)
    y0 = np.concatenate((case.q0, case.v0)).astype(float)
    f(0.0, y0)                                  # warm-up: numba specialization, lambdify
    points = []
    for rtol in rtols:
        wall, y_grid, y_end, _, msg = peers.solver_run(f, y0, case.t_end, t_grid, method, rtol,
                                                       jac=jac, repeats=settings.repeats)
        progress.step(f"{case.stem} {name} rtol={rtol:.0e}")
        if y_grid is None:
            points.append(Point(name, "peer", rtol, wall, failed=str(msg)))
            continue
        points.append(_errors(Point(name, "peer", rtol, wall), mod, p, reference, t_grid,
                              y_grid, y_end))
        if wall > settings.budget:
            progress.step(count=len(rtols) - 1 - rtols.index(rtol))
            break
    return points


def _peer_list(mod, case, p, model_file, settings):
    """[(name, f, jac, scipy method, rtols)] for a case; the sympy.mechanics and PyDy peers only
    for conservative unconstrained models (they derive their own equations)."""
    dop, radau = settings.dop_rtols, settings.radau_rtols
    if case.constrained:
        return [("scipy DOP853 (index-1 KKT)", ref.kkt_rhs(mod, p), None, "DOP853", dop)]
    f = ref.ode_rhs(mod, p)
    out = [("scipy DOP853", f, None, "DOP853", dop),
           ("scipy Radau + Jacobian", f, ref.ode_jacobian(mod, p), "Radau", radau)]
    try:
        fm, _ = peers.mechanics_rhs(model_file, mod.PARAMS, p)
        out.append(("sympy.mechanics + DOP853", fm, None, "DOP853", dop))
        pydy = peers.pydy_rhs(model_file, mod.PARAMS, p)
        if pydy is not None:
            out.append((f"PyDy ({pydy[2]}) + DOP853", pydy[0], None, "DOP853", dop))
    except ValueError:
        pass
    return out


def reference_for_case(mod, case, p, settings):
    t_check = np.linspace(0.0, case.t_end, case.samples + 1)
    q0, v0 = np.array(case.q0, float), np.array(case.v0, float)
    if case.constrained:
        return ref.pendulum_angle_reference(mod, p, q0, v0, case.t_end, t_check)
    return ref.ode_reference(mod, p, q0, v0, case.t_end, t_check, second=settings.second)


def run_case(case, models_dir, gen_dir, settings, methods=None, progress=None):
    """All runs of one case -> dict(case, reference, points, methods, missing)."""
    progress = progress or common.Progress(1, "", enabled=False)
    mod = runs.load_module(models_dir, case.stem, gen_dir)
    p = runs.params_of(mod)
    reference = reference_for_case(mod, case, p, settings)
    wanted = methods_for_case(case, methods)
    points = []
    for method in wanted:
        sweep = sweep_adaptive if registry.spec(method).adaptive else sweep_ours
        points += sweep(mod, method, case, p, reference, settings, progress)
    for name, f, jac, solver, rtols in _peer_list(mod, case, p,
                                                  Path(models_dir) / f"{case.stem}.py", settings):
        points += sweep_peer(name, f, jac, solver, rtols, mod, case, p, reference, settings,
                             progress)
    missing = runs.NOT_AVAILABLE if case.constrained and not wanted else ""
    return {"case": case, "reference": reference, "points": points, "methods": wanted,
            "missing": missing, "model": mod.NAME}


def run_precision(models_dir="models", gen_dir="generated", reports_dir="reports", quick=False,
                  methods=None, cases=None, progress=True):
    """Run the suite, write reports_dir/precision.md and precision_<model>.png; returns
    {"results": [case result], "report": path}."""
    from . import precision_report     # figures and markdown (matplotlib on first use)
    settings = QUICK if quick else FULL
    cases = [c for c in (settings.cases if cases is None else CASES) if cases is None
             or c.stem in cases]
    common.precompile(models_dir, gen_dir, [(c.stem, {}) for c in cases], methods)
    bar = common.Progress(sum(_n_runs(c, settings, methods) for c in cases), "precision",
                          enabled=progress)
    results, lines = [], _intro(settings, quick)
    for case in cases:
        if not runs.model_available(models_dir, case.stem):
            lines += [f"## {case.stem}", "", f"Model file missing: {runs.NOT_AVAILABLE}.", ""]
            continue
        result = run_case(case, models_dir, gen_dir, settings, methods, bar)
        results.append(result)
        name = f"precision_{case.stem}.png"
        precision_report.figure(result, Path(reports_dir) / name)
        if case.stem == "cart_pendulum":
            lines += ["## Headline", "", *precision_report.headline_lines(result)]
        lines += precision_report.case_markdown(result, name)
    bar.finish()
    path = common.write_report(Path(reports_dir) / "precision.md", lines)
    return {"results": results, "report": path}


def methods_for_case(case, methods):
    """Our methods for a case: the constrained ones, or the fixed-step unconstrained ones and
    the adaptive ones; restricted to ``methods`` when given."""
    pool = runs.constrained_methods() if case.constrained else \
        runs.unconstrained_methods() + runs.smooth_adaptive_methods()
    return [m for m in pool if methods is None or m in methods]


def _has_pydy():
    import importlib.util
    return importlib.util.find_spec("pydy") is not None


def _n_runs(case, settings, methods):
    """Runs of a case for the progress bar (sweeps that stop early count what they skip)."""
    ours = sum(len(settings.dop_rtols) if registry.spec(m).adaptive else settings.k_max + 1
               for m in methods_for_case(case, methods))
    dop, radau = len(settings.dop_rtols), len(settings.radau_rtols)
    return ours + (dop if case.constrained else (3 if _has_pydy() else 2) * dop + radau)


def _intro(settings, quick):
    return ["# Work-precision", "",
            f"`lagrange-gen bench precision{' --quick' if quick else ''}`. Ours: every stepper "
            f"through `simulate` at h = h0 / 2^k, k <= {settings.k_max} (the adaptive ones at "
            f"the peers' rtols, atol = rtol / 100); peers: scipy solve_ivp "
            f"on our generated right-hand side (DOP853; Radau with the generated Jacobian), and "
            f"sympy.physics.mechanics LagrangesMethod lambdified + DOP853 on the model's own "
            f"L = T - V, and PyDy's generate_ode_function + DOP853 when pydy is installed "
            f"({'installed' if _has_pydy() else 'not installed for this run'}). Wall time: integration only, min of {settings.repeats} repeats after a "
            f"warm-up, all in one process on a shared 2-core machine (compare ratios, not "
            f"absolute times). Failed runs are listed and drawn as crosses.", ""]
