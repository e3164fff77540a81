"""`lagrange-gen bench stability`: linear stability measured from the steppers themselves, and the
largest stable step of every method on each hard case.

Step matrix (DESIGN.md section 6, Lacoursiere's slides): one step of the real stepper, through
``simulate``, applied to the basis vectors (x, v) = (1, 0) and (0, 1) of the oscillator
x'' = -omega^2 x (models/damped_oscillator.py with b = 0, c = 1 / omega^2); the two results are
the columns of A(tau), tau = h omega. rho(A) = max |eig(A)| decides: > 1 grows, = 1 neither grows
nor damps, < 1 damps. The phase of the eigenvalues per step, against the exact tau, is the
method's frequency error.

Largest stable h: for each scene of bench.scenes and each method, h = h_max / 2^(j/2) downwards
until the run finishes and passes the scene's stability predicate (bench.scenes.STABLE).
"""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np

from ..errors import EnergyWarning
from . import common, scenes

OMEGA = 3.0        # not 1, so that h and tau differ and a wrong scaling would show
TAUS = (0.1, 1.0, 1.9, 1.99, 2.01, 10.0, 1000.0)       # HARD_CASES case 3


def oscillator(models_dir="models", gen_dir="generated"):
    """Generated module of the damped oscillator (the linear test system)."""
    return common.load_module(models_dir, "damped_oscillator", gen_dir)


def step_matrix(mod, method, tau, omega=OMEGA):
    """A (2, 2): columns are one step of ``method`` from (x, v) = (1, 0) and (0, 1) on
    x'' = -omega^2 x with h = tau / omega. Raises SimulationError when the step fails."""
    from ..simulation import simulate
    p = common.params_of(mod, m=1.0, c=1.0 / omega**2, b=0.0)
    h = tau / omega
    cols = []
    for x, v in ((1.0, 0.0), (0.0, 1.0)):
        with warnings.catch_warnings():   # unstable tau are the point of the scan
            warnings.simplefilter("ignore", EnergyWarning)
            tr = simulate(mod, method, [x], [v], t_end=h, h=h, params=p)
        cols.append([tr.q[-1, 0], tr.v[-1, 0]])
    return np.array(cols).T


def spectral_radius(A):
    return float(np.max(np.abs(np.linalg.eigvals(A))))


def phase_per_step(A):
    """Largest |arg(eig(A))|: the angle the method turns per step (the exact one is tau)."""
    return float(np.max(np.abs(np.angle(np.linalg.eigvals(A)))))


# Closed forms of HARD_CASES case 3 (Lacoursiere's slides) and of the other methods.

def verlet_radius(tau):
    """Trace 2 - tau^2, determinant 1: rho = 1 while |1 - tau^2 / 2| <= 1 (tau <= 2)."""
    half_trace = 1.0 - tau**2 / 2
    if abs(half_trace) <= 1.0:
        return 1.0
    return abs(half_trace) + math.sqrt(half_trace**2 - 1.0)


def _verlet_matrix(tau):
    return np.array([[1 - tau**2 / 2, tau], [-tau * (1 - tau**2 / 4), 1 - tau**2 / 2]])


def composition_radius(tau):
    """Yoshida's triple jump: the product of three Verlet matrices with g1 tau, g2 tau, g1 tau."""
    g1 = 1 / (2 - 2 ** (1 / 3))
    g2 = 1 - 2 * g1
    outer, inner = _verlet_matrix(g1 * tau), _verlet_matrix(g2 * tau)
    return spectral_radius(outer @ inner @ outer)


def rk4_radius(tau):
    z = 1j * tau
    return abs(1 + z + z**2 / 2 + z**3 / 6 + z**4 / 24)


CLOSED_FORMS = {
    "explicit_euler": lambda tau: math.sqrt(1 + tau**2),
    "symplectic_euler": verlet_radius,          # same trace and determinant as Verlet
    "verlet": verlet_radius,
    "midpoint": lambda tau: 1.0,
    "implicit_euler": lambda tau: 1 / math.sqrt(1 + tau**2),
    "rk4": rk4_radius,
    "composition": composition_radius,
}


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


def stability_limit(taus, rho, tol=1e-10):
    """Largest tau of the grid below which every measured rho <= 1 + tol; inf when the whole
    grid is stable, 0 when the first point already grows."""
    bad = np.nonzero(~(rho <= 1.0 + tol))[0]
    if len(bad) == 0:
        return math.inf
    return float(taus[bad[0] - 1]) if bad[0] > 0 else 0.0


def tau_table(mod, methods):
    """Rows (method, tau, measured rho, closed-form rho or None) at HARD_CASES case 3's taus."""
    rows = []
    for method in methods:
        closed = CLOSED_FORMS.get(method)
        for tau in TAUS:
            rho = spectral_radius(step_matrix(mod, method, tau))
            rows.append((method, tau, rho, closed(tau) if closed else None))
    return rows


def largest_stable_h(mod, scene, method, p, max_halvings=24, max_steps=2_000_000):
    """(largest stable h on the grid h_max / 2^(j/2), runs tried); None when no h down to the
    step budget is stable. Runs save at most ~20000 rows (the predicates look at saved rows)."""
    q0, v0 = scenes.start_of(scene, mod, p)
    for j in range(2 * max_halvings + 1):
        h = scene.h_max / 2 ** (j / 2)
        n_steps = math.ceil(scene.t_end / h)
        if n_steps > max_steps:
            return None, j
        run = common.guarded_run(mod, method, q0, v0, h, scene.t_end, p,
                                 save_every=max(1, n_steps // 20_000))
        if run.ok and scenes.is_stable(run.traj, scene):
            return h, j + 1
    return None, 2 * max_halvings + 1


def stable_h_table(scene_list, models_dir, gen_dir, methods, progress, max_steps):
    """{scene.key: {method: h or None}} (methods the scene's model takes)."""
    table = {}
    for scene in scene_list:
        if not common.model_available(models_dir, scene.stem):
            table[scene.key] = None
            continue
        mod = common.load_module(models_dir, scene.stem, gen_dir, **scene.options)
        p = common.params_of(mod, **scene.params)
        table[scene.key] = {}
        for method in _methods_for(mod, methods):
            table[scene.key][method], _ = largest_stable_h(mod, scene, method, p,
                                                           max_steps=max_steps)
            progress.step(f"{scene.key} {method}")
    return table


def _methods_for(mod, methods=None):
    """Methods that apply to a module: constrained ones on constrained models, else the rest."""
    pool = common.constrained_methods() if mod.N_CONSTRAINTS else common.unconstrained_methods()
    return [m for m in pool if methods is None or m in methods]


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
    lines += common.md_table(["method", "rho <= 1 for", f"rho at tau = {taus[-1]:g}"], rows)
    lines += ["", "## HARD_CASES case 3: rho at the listed tau, measured vs closed form", ""]
    lines += common.md_table(["method", "tau", "measured rho", "closed form", "abs diff"],
                             [[m, f"{t:g}", f"{r:.12g}", common.fmt(c, ".12g"),
                               common.fmt(None if c is None else abs(r - c), ".1e")]
                              for m, t, r, c in table])
    lines += ["", "## Largest stable h per hard case", "",
              f"h = h_max / 2^(j/2) downwards until the run passes the scene's test "
              f"(runs of at most {max_steps:g} steps; '< h' when none was, '>= h_max' when the "
              f"first was): the energy never "
              f"rises by more than abs(E0)/2 (damping passes, growth fails; n/a: the method "
              f"does not apply to the model), |theta| < pi throughout (separatrix pendulum: "
              f"it must not go over the top).", ""]
    methods = sorted({m for row in stable_h.values() if row for m in row},
                     key=list(common.registry.METHODS).index)
    rows = []
    for scene in scene_list_:
        row = stable_h.get(scene.key)
        cells = [common.NOT_AVAILABLE] * len(methods) if row is None else \
            [_h_cell(row[m], scene, max_steps) if m in row else "n/a" for m in methods]
        rows.append([f"{scene.title} (T = {scene.t_end:g})", *cells])
    lines += common.md_table(["scene", *methods], rows)
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
    ms = _methods_for(mod, methods)
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
