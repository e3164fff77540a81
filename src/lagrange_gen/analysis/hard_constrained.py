"""Hard cases 7 and 8 of HARD_CASES.md: strong springs as the limit of a constraint, and constraint
drift on a closed loop. They need the constrained steppers and models of issue 4; a build
without them reports the case as "not available in this build".
"""

from __future__ import annotations

import math

import numpy as np

from . import reference, scenes
from .hard_cases import FAIL, PASS, CaseResult, selected_methods, verdict_of
from .runs import NOT_AVAILABLE, constrained_methods, guarded_run, has_method, load_module, \
    model_available, params_of, short_error
from ..steppers.core import registry

STIFFNESSES = (1e2, 1e4, 1e6, 1e8)
THETA0 = 0.5           # start angle of the pendulums, rad from the downward vertical
#: "At Newton tolerance": within 100x of simulate's default Newton tolerance 1e-12 (relative to
#: O(1) unknowns); the index-1 form must drift past it.
DRIFT_TOL = 1e-10


def _unavailable(number, title, what):
    return CaseResult(number, title, NOT_AVAILABLE, [], [],
                      [f"Needs {what}: {NOT_AVAILABLE}."])


def _rigid_reference(models_dir, gen_dir, h, t_end):
    """Bob position (2,) at t_end of the rigid pendulum, from the angle form (DOP853 1e-13)."""
    mod = load_module(models_dir, "cartesian_pendulum", gen_dir)
    p = params_of(mod)
    q0 = np.array([math.sin(THETA0), -math.cos(THETA0)])
    ref = reference.pendulum_angle_reference(mod, p, q0, np.zeros(2), t_end,
                                             np.array([t_end]))
    return mod, p, q0, ref.y_end[:2]


def _stretch_row(mod, method, k, q0, h, t_end, rigid_end):
    p = params_of(mod, k=k)
    run = guarded_run(mod, method, q0, np.zeros(2), h, t_end, p)
    if not run.ok:
        return None, "blow-up, " + short_error(run.error)
    dist = float(np.max(np.abs(run.traj.q[-1] - rigid_end)))
    return dist, f"{dist:.2e}"


def case7_stretchable(models_dir, gen_dir, methods, h=0.01, t_end=5.0):
    """Stiffness k = 1e2..1e8 at fixed h: implicit methods never blow up and approach the rigid
    pendulum as k grows; verlet blows up once h omega > 2 (omega = sqrt(k/m)) and says so."""
    title = "stretchable pendulum, k -> inf"
    if not model_available(models_dir, "stretchable_pendulum"):
        return _unavailable(7, title, "models/stretchable_pendulum.py")
    mod = load_module(models_dir, "stretchable_pendulum", gen_dir)
    rigid_mod, rigid_p, q0, rigid_end = _rigid_reference(models_dir, gen_dir, h, t_end)
    rows, oks = [], []
    for method in selected_methods(methods):
        dists, cells = zip(*(_stretch_row(mod, method, k, q0, h, t_end, rigid_end)
                             for k in STIFFNESSES))
        ok, expect = _stretch_verdict(method, dists, h)
        if expect:
            oks.append(ok)
        rows.append([method, *cells, expect or "-", (PASS if ok else FAIL) if expect else "-"])
    if has_method("rattle"):
        run = guarded_run(rigid_mod, "rattle", q0, np.zeros(2), h, t_end, rigid_p)
        dist = float(np.max(np.abs(run.traj.q[-1] - rigid_end))) if run.ok else math.inf
        ok = dist <= 1e-2
        oks.append(ok)
        rows.append(["rattle, rigid (k = inf)", *([f"{dist:.2e}"] * len(STIFFNESSES)),
                     "within 1e-2 of the exact rigid pendulum", PASS if ok else FAIL])
    notes = [f"h = {h:g}, T = {t_end:g}, start at rest at theta = {THETA0} on the rest length "
             f"(the stiff mode starts at rest). Cells: max-norm distance of the bob at T from "
             f"the rigid pendulum (exact, angle form, DOP853 at 1e-13). h omega = 2 at k = "
             f"{(2 / h) ** 2:g}."]
    return CaseResult(7, title, verdict_of(oks),
                      ["method", *(f"k = {k:g}" for k in STIFFNESSES), "expected", "verdict"],
                      rows, notes)


def _stretch_verdict(method, dists, h):
    """(ok, expectation text or '') for one method's row of distances (None = blow-up): an
    A-stable method never blows up and approaches the rigid pendulum; a symplectic method with
    a finite stable range runs while h omega stays in it and reports the blow-up beyond."""
    spec = registry.spec(method)
    if spec.stable_tau is not None and math.isinf(spec.stable_tau):
        ok = all(d is not None for d in dists) and dists[-1] < dists[0]
        return ok, "no blow-up; closer to rigid at k = 1e8 than at 1e2"
    if spec.symplectic and spec.stable_tau:
        expect = [math.sqrt(k) * h <= spec.stable_tau for k in STIFFNESSES]
        ok = all((d is not None) == e for d, e in zip(dists, expect))
        return ok, f"runs while h omega <= {spec.stable_tau:.4g}, blow-up reported beyond"
    return True, ""


def case8_linkage(models_dir, gen_dir, methods, h=1e-3, n_steps=100_000):
    """Closed-loop drift over n_steps: projected methods keep max |Phi| and |J v| at Newton
    tolerance (<= DRIFT_TOL); the index-1 formulation drifts past it."""
    title = f"four-bar linkage: constraint drift over {n_steps:g} steps"
    have = [m for m in constrained_methods() if methods is None or m in methods]
    if not model_available(models_dir, "four_bar") or not have:
        return _unavailable(8, title, "models/four_bar.py and the constrained steppers")
    mod = load_module(models_dir, "four_bar", gen_dir)
    p = params_of(mod)
    q0 = scenes.four_bar_start(mod, p)
    v0 = np.zeros(mod.N_COORDS)
    rows, oks = [], []
    for method in have:
        run = guarded_run(mod, method, q0, v0, h, n_steps * h, p,
                          save_every=max(1, n_steps // 1000))
        if not run.ok:
            rows.append([method, short_error(run.error), "-", "-", "-", FAIL])
            oks.append(False)
            continue
        phi, jv = reference.constraint_residuals(mod, p, run.traj.q, run.traj.v)
        ok, expect = _drift_verdict(method, phi.max(), jv.max())
        if expect:
            oks.append(ok)
        rows.append([method, f"{phi.max():.1e}", f"{jv.max():.1e}",
                     f"{run.traj.max_energy_error:.1e}", expect or "-",
                     (PASS if ok else FAIL) if expect else "-"])
    notes = [f"h = {h:g}, {n_steps:g} steps from rest at th1 = pi/2 (consistent start by "
             f"Newton on Phi); residuals at {min(n_steps, 1000)} sample times."]
    return CaseResult(8, title, verdict_of(oks),
                      ["method", "max abs(Phi)", "max abs(J v)", "max abs(E - E0)", "expected",
                       "verdict"], rows, notes)


def _drift_verdict(method, phi, jv):
    """(ok, expectation) from the method's declared SPEC.constraint_drift."""
    drift = registry.spec(method).constraint_drift
    if drift == "none":
        return phi <= DRIFT_TOL and jv <= DRIFT_TOL, f"both <= {DRIFT_TOL:g}"
    if drift == "grows":
        return phi > DRIFT_TOL, f"abs(Phi) drifts past {DRIFT_TOL:g}"
    return True, ""
