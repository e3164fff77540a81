"""`lagrange-gen bench stability`: rho(tau) curves of every method's step matrix over a grid of tau,
and the largest stable step of every method on each hard case.

The step matrix, spectral radius, phase per step and closed forms are
lagrange_gen.analysis.stability; this module sweeps them and renders the report.

Largest stable h: for each scene of analysis.scenes and each method, h = h_max / 2^(j/2) downwards
until the run finishes and passes the scene's stability predicate (analysis.scenes.STABLE).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from . import common
from ..analysis import runs, scenes
from ..analysis.stability import (OMEGA, TAUS, oscillator, phase_per_step, spectral_radius,
                                  stability_limit, step_matrix, tau_table)
from ..steppers.core import registry


def radius_curves(mod, methods, taus, progress):
    """{method: (rho (T,), phase (T,))} over taus (T,); NaN where a step failed."""
    from ..errors import SimulationError
    curves = {}
    for method in methods:
        rho, phase = np.full(len(taus), np.nan), np.full(len(taus), np.nan)
        for i, tau in enumerate(taus):
            try:
                A = step_matrix(mod, method, tau)
            except SimulationError:
                continue
            rho[i], phase[i] = spectral_radius(A), phase_per_step(A)
        curves[method] = (rho, phase)
        progress.step(f"tau curve {method}")
    return curves


def largest_stable_h(mod, scene, method, p, max_halvings=24, max_steps=2_000_000):
    """(largest stable h on the grid h_max / 2^(j/2), runs tried); None when no h down to the
    step budget is stable. Runs save at most ~20000 rows (the predicates look at saved rows)."""
    q0, v0 = scenes.start_of(scene, mod, p)
    for j in range(2 * max_halvings + 1):
        h = scene.h_max / 2 ** (j / 2)
        n_steps = math.ceil(scene.t_end / h)
        if n_steps > max_steps:
            return None, j
        run = runs.guarded_run(mod, method, q0, v0, h, scene.t_end, p,
                               save_every=max(1, n_steps // 20_000))
        if run.ok and scenes.is_stable(run.traj, scene):
            return h, j + 1
    return None, 2 * max_halvings + 1


def stable_h_table(scene_list, models_dir, gen_dir, methods, progress, max_steps):
    """{scene.key: {method: h or None}} (methods the scene's model takes)."""
    table = {}
    for scene in scene_list:
        if not runs.model_available(models_dir, scene.stem):
            table[scene.key] = None
            continue
        mod = runs.load_module(models_dir, scene.stem, gen_dir, **scene.options)
        p = runs.params_of(mod, **scene.params)
        table[scene.key] = {}
        for method in runs.methods_for(mod, methods):
            table[scene.key][method], _ = largest_stable_h(mod, scene, method, p,
                                                           max_steps=max_steps)
            progress.step(f"{scene.key} {method}")
    return table


def scene_list(quick):
    """The hard cases searched for their largest stable h (shorter runs with quick)."""
    out = [scenes.oscillator_scene(c) for c in (1e-1, 1e-4, 1e-6)]
    out += [scenes.fpu_scene(t_end=10.0 if quick else 50.0),
            scenes.separatrix_scene(periods=2 if quick else 4)]
    return out + scenes.constrained_scenes(quick)


def figure(taus, curves, path):
    """PNG: rho(tau) of every method (log-log) and the phase per step over tau."""
    fig, (a, b) = common.new_figure(1, 2, figsize=(13, 5))
    for i, (method, (rho, phase)) in enumerate(curves.items()):
        # alternate dash styles: symplectic Euler's curve lies exactly on Verlet's
        style = dict(color=f"C{i % 10}", lw=1.5, label=method, ls="-" if i % 2 == 0 else "--")
        a.loglog(taus, rho, **style)
        stable = rho <= 1 + 1e-10
        b.semilogx(taus[stable], phase[stable] / taus[stable], **style)
    a.axhline(1.0, color="k", lw=0.8, ls=":")
    a.axvline(2.0, color="0.6", lw=0.6, ls="--")
    a.set_ylim(1e-3, 1e3)
    a.set_xlabel("tau = h omega")
    a.set_ylabel("spectral radius of the step matrix")
    a.set_title("x'' = -omega^2 x: rho > 1 grows, = 1 keeps, < 1 damps")
    a.legend(fontsize=8)
    b.set_xlabel("tau = h omega")
    b.set_ylabel("phase per step / tau (1 = exact frequency)")
    b.set_title("frequency of the numerical oscillation (where rho <= 1)")
    b.set_ylim(0, 1.5)
    b.grid(True, alpha=0.3)
    return common.save_figure(fig, path)


def _interval(limit):
    if math.isinf(limit):
        return "every measured tau"
    return "no tau > 0" if limit == 0 else f"tau <= {limit:.3g} (grid point)"


def _h_cell(h, scene, max_steps):
    if h is None:
        return f"< {scene.t_end / max_steps:.1e}"
    # stable already at the start of the search: the true limit may be larger
    return f">= {h:.3g}" if h == scene.h_max else f"{h:.3g}"


def markdown(taus, curves, table, stable_h, scene_list_, max_steps, quick):
    lines = ["# Linear stability and the largest stable step", "",
             f"`lagrange-gen bench stability{' --quick' if quick else ''}`. Step matrices "
             f"measured from the steppers (one `simulate` step from the basis vectors of "
             f"x'' = -omega^2 x, omega = {OMEGA:g}), {len(taus)} values of tau.", "",
             "![tau curves](stability_tau.png)", "",
             "## Stability interval (measured)", ""]
    rows = [[m, _interval(stability_limit(taus, rho)), f"{rho[-1]:.3g}"]
            for m, (rho, _) in curves.items()]
    lines += runs.md_table(["method", "rho <= 1 for", f"rho at tau = {taus[-1]:g}"], rows)
    lines += ["", "## HARD_CASES case 3: rho at the listed tau, measured vs closed form", ""]
    lines += runs.md_table(["method", "tau", "measured rho", "closed form", "abs diff"],
                           [[m, f"{t:g}", f"{r:.12g}", runs.fmt(c, ".12g"),
                             runs.fmt(None if c is None else abs(r - c), ".1e")]
                            for m, t, r, c in table])
    lines += ["", "## Largest stable h per hard case", "",
              f"h = h_max / 2^(j/2) downwards until the run passes the scene's test "
              f"(runs of at most {max_steps:g} steps; '< h' when none was, '>= h_max' when the "
              f"first was): the energy never "
              f"rises by more than abs(E0)/2 (damping passes, growth fails; n/a: the method "
              f"does not apply to the model), |theta| < pi throughout (separatrix pendulum: "
              f"it must not go over the top).", ""]
    methods = sorted({m for row in stable_h.values() if row for m in row},
                     key=list(registry.METHODS).index)
    rows = []
    for scene in scene_list_:
        row = stable_h.get(scene.key)
        cells = [runs.NOT_AVAILABLE] * len(methods) if row is None else \
            [_h_cell(row[m], scene, max_steps) if m in row else "n/a" for m in methods]
        rows.append([f"{scene.title} (T = {scene.t_end:g})", *cells])
    lines += runs.md_table(["scene", *methods], rows)
    return lines


def run_stability(models_dir="models", gen_dir="generated", reports_dir="reports", quick=False,
                  methods=None, progress=True, scene_keys=None):
    """Measure, write reports_dir/stability.md and stability_tau.png; returns the numbers.
    methods and scene_keys (Scene.key) restrict the run."""
    taus = np.unique(np.concatenate((np.logspace(-2, 3, 41 if quick else 161), TAUS)))
    scene_list_ = [s for s in scene_list(quick) if scene_keys is None or s.key in scene_keys]
    common.precompile(models_dir, gen_dir, [("damped_oscillator", {})] +
                      [(s.stem, s.options) for s in scene_list_], methods)
    mod = oscillator(models_dir, gen_dir)
    ms = runs.methods_for(mod, methods)
    max_steps = 200_000 if quick else 2_000_000
    bar = common.Progress(len(ms) * (1 + len(scene_list_)), "stability", enabled=progress)
    curves = radius_curves(mod, ms, taus, bar)
    table = tau_table(mod, ms)
    stable_h = stable_h_table(scene_list_, models_dir, gen_dir, methods, bar, max_steps)
    bar.finish()
    figure(taus, curves, Path(reports_dir) / "stability_tau.png")
    path = common.write_report(Path(reports_dir) / "stability.md",
                               markdown(taus, curves, table, stable_h, scene_list_, max_steps,
                                        quick))
    return {"taus": taus, "curves": curves, "tau_table": table, "stable_h": stable_h,
            "scenes": scene_list_, "report": path}
