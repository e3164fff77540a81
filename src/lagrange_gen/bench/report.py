"""`lagrange-gen bench report`: run the precision, stability and hard suites and write
reports/summary.md: the headline and a table telling a user which method to pick for which scene.

Every choice is computed from the measurements of this run, by a stated rule; nothing is typed in:
* energy matters and h omega < 1: the symplectic method that reaches max |E - E0| <= 1e-6 on the
  cart pendulum (T = 10) in the least wall time;
* short smooth runs, accuracy first: the method that reaches final-state error 1e-8 fastest;
* stiff modes the scene does not care about: the method whose measured rho falls furthest below
  1 at the largest tau while staying <= 1 everywhere (L-stability), which damps the stiff mode
  in hard case 4;
* h omega >> 1 and no damping allowed: the method with rho = 1 at every measured tau
  (A-stable, not damping), which keeps the stiff mode in hard case 4;
* constraints: the projected constrained method that reaches final-state error 1e-6 fastest on
  the Cartesian pendulum with max |Phi| <= 1e-10 (hard_constrained.DRIFT_TOL).
"""

from __future__ import annotations

import math
from pathlib import Path

from . import common, hard, precision, precision_report, stability
from ..analysis import hard_constrained, runs
from ..steppers.core import registry

ENERGY_TARGET = 1e-6


def _result(precision_results, stem):
    return next((r for r in precision_results if r["case"].stem == stem), None)


def _fastest(result, methods, key, target, extra=None):
    """(method, seconds) reaching ``target`` in ``key`` fastest among ``methods`` (and
    satisfying extra(points) when given); (None, None) when none does."""
    best = (None, None)
    for method, pts in common.by_method(result["points"]).items():
        if method not in methods or (extra and not extra(pts)):
            continue
        t = common.time_at(pts, target, key)
        if t is not None and (best[1] is None or t < best[1]):
            best = (method, t)
    return best


def _ms(t):
    return f"{t * 1e3:.3g} ms"


def energy_row(prec):
    cart = _result(prec, "cart_pendulum")
    symplectic = [m for m in runs.unconstrained_methods() if registry.INFO[m].symplectic]
    method, t = _fastest(cart, symplectic, "energy", ENERGY_TARGET) if cart else (None, None)
    why = "no symplectic method reached it" if method is None else \
        f"fastest symplectic method to max abs(E - E0) <= {ENERGY_TARGET:g} on the cart " \
        f"pendulum (T = 10): {_ms(t)}; symplectic, so the energy error stays bounded over " \
        f"long runs instead of drifting (FPU, hard case 5)"
    return ["energy matters, h omega < 1", method or "-", why]


def accuracy_row(prec):
    cart = _result(prec, "cart_pendulum")
    pool = runs.unconstrained_methods() + runs.smooth_adaptive_methods()
    method, t = _fastest(cart, pool, "final", common.TARGET) if cart else (None, None)
    why = "-" if method is None else \
        f"fastest to final-state error {common.TARGET:g} on the cart pendulum: {_ms(t)} " \
        f"(energy drifts slowly: not for long runs)"
    return ["short smooth run, accuracy first", method or "-", why]


def _case(hard_results, number):
    return next((r for r in hard_results if r.number == number), None)


def _stiff_outcome(hard_results, method):
    case4 = _case(hard_results, 4)
    if case4 is None:
        return "not run"
    return case4.data["outcomes"].get((1e-6, method), "not run")


def damping_row(stab, hard_results):
    """L-stable choice: stable at every tau, smallest rho at the largest tau."""
    taus, curves = stab["taus"], stab["curves"]
    stable = {m: rho for m, (rho, _) in curves.items() if math.isinf(
        stability.stability_limit(taus, rho))}
    if not stable:
        return ["stiff modes the scene does not care about", "-", "no method stable at every tau"]
    method = min(stable, key=lambda m: stable[m][-1])
    why = (f"rho <= 1 at every measured tau and rho = {stable[method][-1]:.2g} at tau = "
           f"{taus[-1]:g} (the stiff mode is damped in one step); hard case 4 at tau = 10: "
           f"{_stiff_outcome(hard_results, method)}")
    return ["stiff modes the scene does not care about", method, why]


def no_damping_row(stab, hard_results):
    """A-stable and not damping: rho = 1 at every measured tau."""
    taus, curves = stab["taus"], stab["curves"]
    keep = [m for m, (rho, _) in curves.items() if all(abs(r - 1) <= 1e-10 for r in rho)]
    if not keep:
        return ["h omega >> 1, no damping allowed", "-", "no method has rho = 1 at every tau"]
    method = keep[0]
    why = (f"rho = 1 at every measured tau up to {taus[-1]:g}; hard case 4 at tau = 10: "
           f"{_stiff_outcome(hard_results, method)}; the stiff mode's frequency is not "
           f"resolved (phase 2 atan(tau/2) per step instead of tau)")
    return ["h omega >> 1, no damping allowed", method, why]


def constraints_row(prec, hard_results):
    cart = _result(prec, "cartesian_pendulum")
    projected = [m for m in runs.constrained_methods()
                 if registry.spec(m).constraint_drift == "none"]
    if cart is None or not projected:
        return ["constraints", "-", runs.NOT_AVAILABLE]

    def on_manifold(pts):
        return all(pt.phi <= hard_constrained.DRIFT_TOL for pt in pts if not pt.failed)
    method, t = _fastest(cart, projected, "final", 1e-6, on_manifold)
    case8 = _case(hard_results, 8)
    drift = f"; linkage drift (hard case 8): {case8.verdict}" if case8 else ""
    why = "no projected method reached final error 1e-6" if method is None else \
        f"fastest projected method to final error 1e-6 on the Cartesian pendulum with max " \
        f"abs(Phi) <= {hard_constrained.DRIFT_TOL:g}: {_ms(t)}{drift}"
    return ["constraints", method or "-", why]


def choice_rows(prec, stab, hard_results):
    """[scene, pick, why] rows of the method-choice table."""
    return [energy_row(prec), accuracy_row(prec), damping_row(stab, hard_results),
            no_damping_row(stab, hard_results), constraints_row(prec, hard_results)]


def choice_table(prec, stab, hard_results):
    """Markdown lines of the method-choice table."""
    return runs.md_table(["scene", "pick", "why (measured in this run)"],
                         choice_rows(prec, stab, hard_results))


def run_report(models_dir="models", gen_dir="generated", reports_dir="reports", quick=False,
               progress=True, methods=None, precision_cases=None, scene_keys=None,
               hard_cases=None):
    """All three suites, then reports_dir/summary.md; returns the suites' results. methods,
    precision_cases, scene_keys and hard_cases restrict the suites (tests use them)."""
    kw = dict(models_dir=models_dir, gen_dir=gen_dir, reports_dir=reports_dir, quick=quick,
              progress=progress, methods=methods)
    prec = precision.run_precision(cases=precision_cases, **kw)
    stab = stability.run_stability(scene_keys=scene_keys, **kw)
    hrd = hard.run_hard(cases=hard_cases, **kw)
    lines = ["# Benchmark summary", "",
             f"`lagrange-gen bench report{' --quick' if quick else ''}` (precision, stability, "
             f"hard in one run; details in [precision.md](precision.md), "
             f"[stability.md](stability.md), [hard.md](hard.md)).", ""]
    cart = _result(prec["results"], "cart_pendulum")
    if cart:
        lines += ["## Headline", "", *precision_report.headline_lines(cart),
                  "![cart pendulum work-precision](precision_cart_pendulum.png)", ""]
    lines += ["## Which method for which scene", "",
              *choice_table(prec["results"], stab, hrd["results"]), "",
              "## Hard cases", "",
              *runs.md_table(["case", "verdict"], [[f"{r.number}: {r.title}", r.verdict]
                                                   for r in hrd["results"]])]
    path = common.write_report(Path(reports_dir) / "summary.md", lines)
    return {"precision": prec, "stability": stab, "hard": hrd, "report": path}
