"""`lagrange-gen bench hard`: the hard cases 3-8 of HARD_CASES.md, each with a verdict against its
reference, a table and (cases 4 and 5) a figure; writes reports/hard.md.

The cases and their verdicts are lagrange_gen.analysis.hard_cases (3-6) and
analysis.hard_constrained (7-8); this module runs them, draws the figures and writes the report.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..analysis import hard_cases, hard_constrained, reference, runs, scenes, stability
from . import common


#: Models of each case, for precompile: [(stem, build options)].
CASE_MODELS = {3: [("damped_oscillator", {})], 4: [("damped_oscillator", {})],
               5: [("fpu", {})], 6: [("n_link_pendulum", {"n": 1})],
               7: [("stretchable_pendulum", {}), ("cartesian_pendulum", {})],
               8: [("four_bar", {})]}


def run_cases(models_dir, gen_dir, methods=None, quick=False, cases=None, progress=None):
    """Run the selected case numbers (default 3-8) -> [CaseResult]. quick shortens case 8
    (1e4 instead of 1e5 steps); the others are cheap at their fixed h."""
    progress = progress or common.Progress(1, "", enabled=False)
    wanted = cases or (3, 4, 5, 6, 7, 8)
    runners = {
        3: lambda: hard_cases.case3_tau(stability.oscillator(models_dir, gen_dir), methods),
        4: lambda: hard_cases.case4_damped(models_dir, gen_dir, methods),
        5: lambda: hard_cases.case5_fpu(models_dir, gen_dir, methods),
        6: lambda: hard_cases.case6_separatrix(models_dir, gen_dir, methods),
        7: lambda: hard_constrained.case7_stretchable(models_dir, gen_dir, methods),
        8: lambda: hard_constrained.case8_linkage(models_dir, gen_dir, methods,
                                                  n_steps=10_000 if quick else 100_000),
    }
    results = []
    for number in wanted:
        results.append(runners[number]())
        progress.step(f"case {number}")
    return results


def fpu_figure(result, path):
    """I_1, I_2, I_3 against t for each method that ran, with the published reference points."""
    series = result.data["series"]
    shown = [m for m in ("verlet", "midpoint", "composition", "rk4") if m in series] or \
        list(series)[:4]
    if not shown:
        return None
    fig, axes = common.new_figure(1, len(shown), figsize=(4.2 * len(shown), 3.8), sharey=True,
                                  squeeze=False)
    ref_t = list(reference.FPU_REFERENCE)
    ref_i = np.array(list(reference.FPU_REFERENCE.values()))
    for ax, method in zip(axes[0], shown):
        t, I = series[method]
        for j in range(3):
            ax.plot(t, I[:, j], color=f"C{j}", lw=0.8, label=f"I_{j + 1}")
            ax.plot(ref_t, ref_i[:, j], ls="none", marker="o", mfc="none", color=f"C{j}")
        ax.plot(t, I.sum(axis=1), color="k", lw=0.6, label="sum")
        ax.set_title(method)
        ax.set_xlabel("t")
    axes[0][0].set_ylabel("oscillatory energy (circles: reference)")
    axes[0][0].legend(fontsize=7)
    return common.save_figure(fig, path)


def damped_figure(result, path, compliance=1e-6):
    """E(t)/E0 of every method at the stiffest compliance, log scale, against the exact one;
    a run that failed is a cross at its failure time on the top edge."""
    by_method = {m: v for (c, m), v in result.data["energies"].items() if c == compliance}
    if not by_method:
        return None
    fig, ax = common.new_figure(figsize=(7, 4.5))
    top = 1e3
    for i, (method, run) in enumerate(by_method.items()):
        style = dict(color=f"C{i}", ls="-" if i % 2 == 0 else "--")
        if isinstance(run, tuple):
            t, e = run
            ax.semilogy(t, np.clip(e, 1e-300, top), label=method, **style)
        else:
            ax.semilogy([run], [top / 2], marker="x", ms=9, ls="none", color=style["color"],
                        label=f"{method}: failed (blow-up) at t = {run:.3g}")
    sc = scenes.oscillator_scene(compliance)
    t = np.linspace(0, sc.t_end, 2001)
    x, v = reference.oscillator_exact(t, 1.0, compliance, sc.params["b"])
    ax.semilogy(t, (0.5 * v**2 + 0.5 * x**2 / compliance) * 2 * compliance, "k:", lw=1.5,
                label="exact")
    ax.set_ylim(1e-12, top)
    ax.set_xlabel("t")
    ax.set_ylabel("E / E0")
    ax.set_title(f"damped oscillator, c = {compliance:g}, h = {sc.h:g} (tau = "
                 f"{sc.h / np.sqrt(compliance):g})")
    ax.legend(fontsize=7, loc="center right")
    return common.save_figure(fig, path)


def case_markdown(result):
    lines = [f"## Case {result.number}: {result.title} — **{result.verdict}**", ""]
    lines += result.notes + ([""] if result.notes else [])
    if result.rows:
        lines += runs.md_table(result.headers, result.rows) + [""]
    lines += [f"![case {result.number}]({name})" for name in result.figures]
    return lines + ([""] if result.figures else [])


def markdown(results, quick):
    lines = ["# Hard cases", "",
             f"`lagrange-gen bench hard{' --quick' if quick else ''}`: the cases of "
             f"HARD_CASES.md 3-8, each judged against its reference (closed form, published "
             f"values, elliptic functions, the exact rigid pendulum). A case passes when every "
             f"expectation it states holds; rows without an expectation are reported only.", ""]
    lines += runs.md_table(["case", "verdict"],
                           [[f"{r.number}: {r.title}", r.verdict] for r in results]) + [""]
    for r in results:
        lines += case_markdown(r)
    return lines


def run_hard(models_dir="models", gen_dir="generated", reports_dir="reports", quick=False,
             methods=None, cases=None, progress=True):
    """Run the cases, write reports_dir/hard.md and its figures; returns the CaseResults."""
    wanted = cases or (3, 4, 5, 6, 7, 8)
    stems = {(stem, tuple(opts.items())) for n in wanted for stem, opts in CASE_MODELS[n]}
    common.precompile(models_dir, gen_dir, [(s, dict(o)) for s, o in sorted(stems)], methods)
    bar = common.Progress(len(wanted), "hard", enabled=progress)
    results = run_cases(models_dir, gen_dir, methods, quick, wanted, bar)
    bar.finish()
    figures = {4: ("hard_damped_oscillator.png", damped_figure),
               5: ("hard_fpu.png", fpu_figure)}
    for r in results:
        if r.number in figures and r.verdict != runs.NOT_AVAILABLE:
            name, draw = figures[r.number]
            if draw(r, Path(reports_dir) / name) is not None:
                r.figures.append(name)
    path = common.write_report(Path(reports_dir) / "hard.md", markdown(results, quick))
    return {"results": results, "report": path}
