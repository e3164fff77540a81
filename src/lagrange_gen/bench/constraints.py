"""Measurements of the constrained steppers (issue 4), written to reports/constraints.md.

    python -m lagrange_gen.bench.constraints [--quick]

1. Drift on the closed-loop four-bar linkage (models/four_bar.py, HARD_CASES case 8): max |Phi|
   and max |J v| over 1e5 steps per constrained method, with the index-1 formulation with and
   without Baumgarte stabilization as the bad example, the energy error and the cost per step.
2. Cost per step on the Cartesian pendulum: every constrained method against verlet on its free
   twin (the same T and V without the constraint, generated alongside: free fall, the same
   kernels; constrained modules carry no unconstrained glue), best of several runs in one process.
3. Stretchable pendulum (models/stretchable_pendulum.py, case 7) at fixed h with k = 1e2..1e12:
   where each method breaks (blow-up or Newton failure) and how far it is from the rigid
   pendulum integrated by rattle; spook runs the rigid model with compliance 1/k.

All runs go through lagrange_gen.simulate (wall times exclude compilation).
"""

from __future__ import annotations

import sys
import warnings
from pathlib import Path

import numpy as np

from ..analysis.runs import fmt, md_table
from .common import ROOT, new_figure, save_figure, write_report
from ..errors import EnergyWarning, SimulationError
from ..run.consistent import consistent_initial_state
from ..run.simulate import simulate
from .steppers import best_of
from ..steppers.core.layout import N_STATS, events_size, last_size
from ..steppers.core.method_spec import make_settings
from ..steppers.core.registry import spec

LINKAGE_H = 1e-3
STIFF_H, STIFF_T, STIFF_THETA0 = 1e-3, 2.0, 1.0
BAUMGARTE = (10.0, 10.0)
#: (label, method, simulate keyword arguments) of the linkage table.
LINKAGE_RUNS = (
    ("rattle", "rattle", {}),
    ("constrained_midpoint", "constrained_midpoint", {}),
    ("constrained_implicit_euler", "constrained_implicit_euler", {}),
    ("spook (epsilon = 0, d = 2)", "spook", {}),
    ("index1 (rk4, no stabilization)", "index1", {}),
    (f"index1 + Baumgarte alpha = beta = {BAUMGARTE[0]:g}", "index1", {"baumgarte": BAUMGARTE}),
)
#: A bob farther than this from the pivot (rest length 1) counts as broken even without a
#: blow-up past simulate's bound (explicit Euler's energy grows, but slowly).
WRONG = 10.0
STIFF_METHODS = ("explicit_euler", "symplectic_euler", "verlet", "composition", "rk4",
                 "midpoint", "implicit_euler", "spook")


def _load(models_dir, stem, gen_dir):
    from ..run.loader import load
    return load(Path(models_dir) / f"{stem}.py", out_dir=gen_dir)


def _free_twin(models_dir, stem):
    """The model of models_dir/<stem>.py without its constraints, generated with verlet's glue
    as <name>_free into a bench directory under the system temp dir (not generated/: it is no
    model file's module): the baseline that has the same kernels but no constraint."""
    import tempfile
    from ..codegen.generate import generate_text
    from ..codegen.write import write_if_changed
    from ..model.model import Model
    from ..model.model_file import load_model
    from ..run.loader import import_generated
    rigid = load_model(Path(models_dir) / f"{stem}.py")
    free = Model(f"{rigid.name}_free", rigid.coords, rigid.T, rigid.V, forces=rigid.forces,
                 dissipation=rigid.dissipation, params=rigid.params)
    free.source_path, free.source_text = rigid.source_path, rigid.source_text
    gen_dir = Path(tempfile.gettempdir()) / "lagrange_gen_bench_twins"
    text, _, target = generate_text(free, gen_dir, ["verlet"])
    gen_dir.mkdir(parents=True, exist_ok=True)
    write_if_changed(target, text)
    return import_generated(target)


def linkage_drift(mod, n_steps):
    """Rows {label, max_phi, end_phi, max_jv, energy, ns, iters} and the |Phi|(t) curves."""
    p = np.array(mod.DEFAULTS)
    # The swinging linkage: crank released at rest near 0.3 rad (projected onto the loop).
    state = consistent_initial_state(mod, [0.3, 0.83, 1.57], [0.0, 0.0, 0.0], p, warn=False)
    save = max(1, n_steps // 2000)
    rows, curves = [], {}
    for label, method, kwargs in LINKAGE_RUNS:
        traj = simulate(mod, method, state.q, state.v, t_end=n_steps * LINKAGE_H, h=LINKAGE_H,
                        save_every=save, **kwargs)
        rows.append(dict(label=label, max_phi=traj.constraint_error.max(),
                         end_phi=traj.constraint_error[-1],
                         max_jv=traj.velocity_constraint_error.max(),
                         energy=traj.max_energy_error, ns=traj.wall_time / n_steps * 1e9,
                         iters=traj.newton_iters[1:].sum() / n_steps))
        curves[label] = (traj.t, traj.constraint_error)
    return rows, curves


def _glue_runner(mod, method, n_steps, q0, v0):
    """A closure running n_steps of run_<method> with only the final state saved."""
    n, m = mod.N_COORDS, mod.N_CONSTRAINTS
    constrained = spec(method).constraints
    n_saved = spec(method).n_saved(n, m, mod.N_ELEMENTS)
    extra = np.zeros((2, n_saved))
    if constrained:
        extra[0, :m] = consistent_initial_state(mod, q0, v0, mod.DEFAULT_PARAMS, warn=False).lam
    out = (np.empty(2), np.empty((2, n)), np.empty((2, n)), np.empty((2, N_STATS)), extra,
           np.empty(last_size(n, n_saved)), np.empty((0, events_size(n))))
    settings = make_settings(spec(method), {})
    run = getattr(mod, f"run_{method}")

    def go():
        status, _, _ = run(q0, v0, 0.0, LINKAGE_H, n_steps, n_steps, mod.DEFAULT_PARAMS,
                           settings, *out)
        if status != 0:
            raise RuntimeError(f"bench constraints: {method} failed with status {status}")
        return out[3][1, 1] / n_steps
    return go


def step_costs(mod, free, n_steps, repeats):
    """Rows {method, ns, iters} on the Cartesian pendulum ``mod``, verlet first (on ``free``, its
    unconstrained twin; same run)."""
    q0 = np.array([np.sin(1.0), -np.cos(1.0)])
    v0 = np.zeros(2)
    rows = []
    for method in ("verlet", "rattle", "constrained_midpoint", "constrained_implicit_euler",
                   "spook", "index1"):
        go = _glue_runner(mod if spec(method).constraints else free, method, n_steps, q0, v0)
        go()                                                     # compile or load
        best, iters = best_of(go, repeats)
        rows.append(dict(method=method, ns=best / n_steps * 1e9, iters=iters))
    return rows


def _pendulum(theta, l=1.0):
    return np.array([l * np.sin(theta), -l * np.cos(theta)])


def _spring_run(spring, rigid, method, k, t_end):
    """Trajectory of the stretchable pendulum with stiffness k (spook: the rigid model with
    compliance 1/k); the stiff mode starts at rest (spring at its static stretch, m = l = 1)."""
    if "compliance" in spec(method).setting_names():
        return simulate(rigid, method, _pendulum(STIFF_THETA0), np.zeros(2), t_end=t_end,
                        h=STIFF_H, compliance=1.0 / k)
    q0 = _pendulum(STIFF_THETA0, 1.0 + 9.81 * np.cos(STIFF_THETA0) / k)
    with warnings.catch_warnings():   # the scan looks for where methods break, on purpose
        warnings.simplefilter("ignore", EnergyWarning)
        return simulate(spring, method, q0, np.zeros(2), t_end=t_end, h=STIFF_H, params={"k": k})


def _attempt(spring, rigid, method, k, t_end):
    """(trajectory, '') of the run at stiffness k, or (None, why it broke)."""
    try:
        traj = _spring_run(spring, rigid, method, k, t_end)
    except SimulationError as exc:
        return None, type(exc).__name__
    if np.hypot(traj.q[:, 0], traj.q[:, 1]).max() > WRONG:
        return None, "unbounded"
    return traj, ""


def breaking_stiffness(spring, rigid, method, k_ok, k_bad, t_end, rel=0.01):
    """Bisection in log k between a stiffness that runs and one that breaks: the breaking k to
    about ``rel`` relative precision."""
    while k_bad / k_ok > 1.0 + rel:
        mid = np.sqrt(k_ok * k_bad)
        if _attempt(spring, rigid, method, mid, t_end)[1]:
            k_bad = mid
        else:
            k_ok = mid
    return k_bad


def stiffness_scan(spring, rigid, ks, t_end):
    """{method: [(k, distance to rigid rattle or None, failure text)]} and {method: (first k
    where it fails or the bob strays beyond WRONG, why)}."""
    ref = simulate(rigid, "rattle", _pendulum(STIFF_THETA0), np.zeros(2), t_end=t_end,
                   h=STIFF_H)
    table, breaks = {}, {}
    for method in STIFF_METHODS:
        table[method] = []
        for k in ks:
            traj, why = _attempt(spring, rigid, method, k, t_end)
            if why:
                table[method].append((k, None, why))
                if method not in breaks:
                    k_ok = ks[ks.index(k) - 1] if ks.index(k) else k / 10.0
                    breaks[method] = (breaking_stiffness(spring, rigid, method, k_ok, k, t_end),
                                      why)
                continue
            table[method].append((k, float(np.abs(traj.q - ref.q).max()), ""))
    return table, breaks


def _drift_figure(curves, path):
    fig, ax = new_figure(figsize=(8, 4.5))
    for label, (t, err) in curves.items():
        ax.semilogy(t[1:], np.maximum(err[1:], 1e-17), label=label, lw=1)
    ax.set_xlabel("t")
    ax.set_ylabel("max |Phi(q)|")
    ax.set_title("four-bar linkage, h = 1e-3: constraint drift")
    ax.legend(fontsize=7, loc="center right")
    return save_figure(fig, path)


def _markdown(linkage, n_link, costs, n_cost, table, breaks, ks, t_end, figure):
    lines = ["# Constraints: drift, cost, stiffness", "",
             "`python -m lagrange_gen.bench.constraints` (issue 4). Newton tolerance 1e-12 "
             "(simulate's default); wall times exclude compilation.", "",
             f"## Four-bar linkage, {n_link} steps of h = {LINKAGE_H:g}", "",
             "Closed loop (models/four_bar.py: crank-rocker, H(q) not constant), crank released "
             "at rest at 0.3 rad; max over the saved states of every step's residuals.", ""]
    lines += md_table(["method", "max abs(Phi)", "abs(Phi) at the end", "max abs(J v)",
                       "max abs(E - E0)", "ns/step", "Newton it./step"],
                      [[r["label"], fmt(r["max_phi"]), fmt(r["end_phi"]), fmt(r["max_jv"]),
                        fmt(r["energy"]), fmt(r["ns"], ".0f"), fmt(r["iters"], ".2f")]
                       for r in linkage])
    lines += ["", f"![drift]({figure.name})", "",
              "The projected methods solve Phi(q_n+1) = 0 by Newton and project v onto J v = 0 "
              "every step: their residuals stay at round-off for the whole run. spook keeps a "
              "bounded O(h^2) violation (regularized, stabilized). index1 enforces only "
              "Phi'' = 0: its |Phi| grows with t; Baumgarte's terms bound it at the price of a "
              "tuned bias. implicit Euler's energy error is its numerical damping.", "",
              f"## Cost per step on the Cartesian pendulum ({n_cost} steps, best of several)",
              "", "Same process; verlet runs the model's free twin (the same T and V without the "
              "constraint: free fall with the same kernels), so the difference is the constraint "
              "machinery.", ""]
    verlet = costs[0]["ns"]
    lines += md_table(["method", "ns/step", "x verlet", "Newton it./step"],
                      [[r["method"], fmt(r["ns"], ".0f"), fmt(r["ns"] / verlet, ".1f"),
                        fmt(r["iters"], ".2f")] for r in costs])
    lines += ["", f"## Stretchable pendulum, h = {STIFF_H:g}, t = 0..{t_end:g}, k = "
              f"{ks[0]:g}..{ks[-1]:g}", "",
              "Distance max_t |q - q_rigid| to the rigid pendulum integrated by rattle at the "
              "same h; spook runs the rigid model with compliance 1/k. The radial mode has "
              "omega = sqrt(k), so h omega = 2 at k = 4e6. 'breaks at k': the smallest k (by "
              "bisection, 1 %) with a blow-up, a Newton failure, or the bob farther than "
              f"{WRONG:g} from the pivot within the run; linear stability limits of the explicit "
              "methods: h omega = 2 (verlet, symplectic Euler), 2.83 (rk4), 1.57 (composition), "
              "0 (explicit Euler, whose growth is slow at small h omega).", ""]
    headers = ["method", "breaks at k", "h omega there"] + [f"{k:.0e}" for k in ks]
    rows = []
    for method, cells in table.items():
        where = breaks.get(method)
        rows.append([method, f"{where[0]:.3g} ({where[1]})" if where else "never",
                     f"{STIFF_H * np.sqrt(where[0]):.3g}" if where else "-"]
                    + [fmt(d, ".1e") if d is not None else err for _, d, err in cells])
    lines += md_table(headers, rows)
    lines += ["", "Explicit methods break where h omega passes their stability limit; midpoint "
              "stays bounded (A-stable) and tends to the rigid solution; implicit Euler and "
              "spook stay bounded and converge to their own rigid limits, within O(h) of rattle."]
    return lines


def run_constraints_bench(report_path=ROOT / "reports" / "constraints.md", quick=False,
                          models_dir=ROOT / "models", gen_dir=ROOT / "generated"):
    """Measure, write the markdown report (and a drift figure beside it), return the numbers."""
    report_path = Path(report_path)
    n_link, n_cost, repeats = (10_000, 100_000, 2) if quick else (100_000, 1_000_000, 5)
    ks = tuple(10.0 ** e for e in (range(2, 13, 2) if quick else range(2, 13)))
    t_end = 0.5 if quick else STIFF_T
    linkage, curves = linkage_drift(_load(models_dir, "four_bar", gen_dir), n_link)
    rigid = _load(models_dir, "cartesian_pendulum", gen_dir)
    costs = step_costs(rigid, _free_twin(models_dir, "cartesian_pendulum"), n_cost, repeats)
    table, breaks = stiffness_scan(_load(models_dir, "stretchable_pendulum", gen_dir), rigid,
                                   ks, t_end)
    figure = _drift_figure(curves, report_path.with_name("constraints_drift.png"))
    lines = _markdown(linkage, n_link, costs, n_cost, table, breaks, ks, t_end, figure)
    write_report(report_path, lines)
    return dict(linkage=linkage, costs=costs, stiffness=table, breaks=breaks,
                report="\n".join(lines))


if __name__ == "__main__":
    print(run_constraints_bench(quick="--quick" in sys.argv)["report"])
