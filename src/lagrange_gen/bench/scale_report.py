"""Markdown table, goal verdicts and the log-log figure of `lagrange-gen bench scale`."""

from __future__ import annotations

from pathlib import Path

#: The sizes the goals are stated at: derive + emit + compile against LagrangesMethod, and end to end.
GOAL_N, END_TO_END_N = 16, 20


def _fmt(value, digits=2):
    return "-" if value is None else f"{value:.{digits}f}"


def _ours(row):
    """derive + emit + first compile of the kernels (seconds)."""
    return row["derive"] + row["emit"] + row["module_import"] + row["kernels_compile"]


#: The stages of a first simulate of a new model, as (label, row key).
STAGES = (("derive", "derive"), ("emit", "emit"), ("kernel compile", "kernels_compile"),
          ("glue compile", "glue_compile"))


def dominant_stage(row):
    """'glue compile (62 %)': the stage of derive, emit, kernel and glue compile that takes the
    largest share of their sum in this row."""
    times = {label: row[key] for label, key in STAGES}
    label = max(times, key=times.get)
    return f"{label} ({100 * times[label] / sum(times.values()):.0f} %)"


def _table(rows, lm, budget):
    head = ("| n | derive s | emit s | lines | ops (CSE'd) | kernels 1st compile s | glue 1st compile s "
            "| dominant stage | cached import + 1st step s | ns / forward dyn. | ns / verlet step "
            "| ns / midpoint step | sympy LagrangesMethod s |")
    lines = [head, "|" + "---|" * 13]
    for r in rows:
        ref = lm.get(r["n"])
        lines.append(f"| {r['n']} | {_fmt(r['derive'])} | {_fmt(r['emit'])} | {r['lines']} | {r['ops']} | "
                     f"{_fmt(r['kernels_compile'])} | {_fmt(r['glue_compile'])} | {dominant_stage(r)} | "
                     f"{_fmt(r['cached_first_step'], 3)} | "
                     f"{r['ns_forward']:.0f} | {r['ns_verlet']:.0f} | {r['ns_midpoint']:.0f} | "
                     f"{_fmt(ref) if ref is not None else f'> {budget:.0f} (skipped)'} |")
    return lines


def _verdict(ok):
    return "**met**" if ok else "**missed**"


def _goals(rows, lm, peers):
    by_n = {r["n"]: r for r in rows}
    out = []
    if GOAL_N in by_n:
        ours, ref = _ours(by_n[GOAL_N]), lm.get(GOAL_N)
        if ref:
            out.append(f"- {GOAL_N} links: derive + emit + first compile of the kernels {ours:.1f} s against "
                       f"LagrangesMethod's derive alone {ref:.1f} s: ratio {ours / ref:.3f} (goal <= 0.2) "
                       f"{_verdict(ours / ref <= 0.2)}. With the verlet and midpoint glue compiled too: "
                       f"{ours + by_n[GOAL_N]['glue_compile']:.1f} s, ratio "
                       f"{(ours + by_n[GOAL_N]['glue_compile']) / ref:.3f}.")
        else:
            out.append(f"- {GOAL_N} links: LagrangesMethod exceeded the budget, ratio not measured.")
        first = by_n[GOAL_N]["cached_first_step"]
        out.append(f"- Second process, warm numba cache: import of the {GOAL_N}-link module and its first "
                   f"verlet step {first:.3f} s beyond the numba/numpy/lagrange_gen imports (goal < 1 s) "
                   f"{_verdict(first < 1.0)}.")
    if END_TO_END_N in by_n:
        r = by_n[END_TO_END_N]
        total = _ours(r) + r["glue_compile"]
        out.append(f"- {END_TO_END_N} links end to end (derive, emit, first compile of kernels and of the "
                   f"verlet + midpoint glue, first steps): {total:.1f} s (goal < 60 s) {_verdict(total < 60)}.")
    for name, label in (("pydy", "PyDy (cython RHS)"), ("mujoco", "MuJoCo")):
        state = "installed but not wired into this bench" if peers[name] else "not installed"
        out.append(f"- {label}: {state}; no comparison is reported (no numbers invented).")
    return out


def _figure(path, rows, lm):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    n = [r["n"] for r in rows]
    fig, ax = plt.subplots(figsize=(7, 4.5))
    series = [("derive + emit", [r["derive"] + r["emit"] for r in rows]),
              ("kernels first compile", [r["kernels_compile"] for r in rows]),
              ("glue first compile (verlet + midpoint)", [r["glue_compile"] for r in rows]),
              ("cached import + first step", [r["cached_first_step"] for r in rows])]
    for label, values in series:
        ax.loglog(n, values, "o-", label=label)
    known = [(k, v) for k, v in sorted(lm.items()) if v is not None]
    if known:
        ax.loglog([k for k, _ in known], [v for _, v in known], "s--", color="k",
                  label="sympy LagrangesMethod derive")
    ax.set_xlabel("links n")
    ax.set_ylabel("seconds")
    ax.set_title("n-link pendulum: pipeline cost against n (one run)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def write_report(reports_dir: Path, rows, lm, exceeded, budget, extra, peers, methods):
    """Write scale.md and scale.png under reports_dir (``methods``: those the modules were
    generated with); returns the markdown text."""
    reports_dir.mkdir(parents=True, exist_ok=True)
    _figure(reports_dir / "scale.png", rows, lm)
    lines = ["# Scale: n-link pendulum", "",
             "`lagrange-gen bench scale` (one run; times in seconds on a shared 2-core machine under load, "
             "so compare ratios within this run rather than absolute values).",
             f"Modules generated with `--methods {','.join(methods)}`; compile times from fresh processes with "
             "empty numba caches; ns inside jitted loops (simulate's timed run, forward dynamics: min of 3).", ""]
    lines += _table(rows, lm, budget)
    lines += ["", f"LagrangesMethod: form_lagranges_equations + mass_matrix + forcing, per-case budget {budget:.0f} s"
              + (f"; n = {exceeded} exceeded it, larger n skipped." if exceeded else "; no case exceeded it.")]
    if extra:
        lines += ["", f"Default module (all methods, {extra['count']} kernels) at n = {extra['n']}: derive "
                  f"{extra['derive']:.2f} s, emit {extra['emit']:.2f} s, {extra['lines']} lines, {extra['ops']} ops, "
                  f"kernels first compile {extra['kernels_compile']:.1f} s (including the module import); "
                  f"forward dynamics {extra['ns_forward']:.0f} ns per call (fused symbolic dynamics; the "
                  f"verlet/midpoint module composes dynamics from its other kernels, see codegen/compose.py)."]
    lines += ["", "## Goals", ""] + _goals(rows, lm, peers)
    lines += ["", "![pipeline cost against n](scale.png)", ""]
    text = "\n".join(lines)
    (reports_dir / "scale.md").write_text(text)
    return text
