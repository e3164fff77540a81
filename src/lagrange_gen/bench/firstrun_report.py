"""reports/firstrun.md from the rows of bench/firstrun.py: the model-file-to-first-step table,
its phases, the library compile, the goals of issue 40 with a verdict each, the cost per call."""

from __future__ import annotations

import math

from ..analysis.runs import md_table

VARIANT_TITLES = {"empty": "empty caches", "library": "warm library", "again": "again (new process)",
                  "empty, numba": "empty caches, numba kernels",
                  "library, numba": "warm library, numba kernels"}
VARIANTS = tuple(VARIANT_TITLES)
#: The variant a goal is judged on, in order of preference: the library is compiled once per
#: installation, so a model's first step is judged with it warm; "a new process" and "unchanged"
#: goals on the run that finds everything cached.
JUDGED = {"again": ("again",), "default": ("library", "empty")}
#: Baseline of the per-call goal: UR5 forward_dynamics from Python (reports/robots.md, issue 28).
UR5_BASELINE_NS = 740.0
#: A per-call or per-step ratio within this of 1 is "no regression" on a loaded machine.
NOISE = 1.15
MEMORY_GOAL_MB = 2048.0
MEMORY_CASES = ("humanoid", "12 links")


def seconds(row):
    """The cell of a row: CPU seconds, '> T s (killed in ...)' or 'failed: ...'."""
    if row is None:
        return "-"
    if row.get("timeout"):
        return f"> {row['timeout']:.0f} s ({row['where']})"
    if row.get("error"):
        return f"failed ({row['where']}: {row['error'][:80]})"
    return f"{row['cpu']:.2f}"


def ok(row):
    return row is not None and not row.get("timeout") and not row.get("error")


def first_step_table(cases, results):
    variants = [v for v in VARIANTS if any(v in case.variants for case in cases)]
    rows = []
    for case in cases:
        cells = [seconds(results[case.label].get(v)) for v in variants]
        peak = max((r["rss_mb"] for r in results[case.label].values()), default=float("nan"))
        jit = next((r.get("jit") for r in results[case.label].values() if r.get("jit")), "")
        rows.append([case.label, *cells, f"{peak:.0f}", jit or "-"])
    return md_table(["case", *(VARIANT_TITLES[v] for v in variants), "peak MB", "loop"], rows)


def phase_table(cases, results):
    rows = []
    for case in cases:
        for variant, row in results[case.label].items():
            if not row["phases"]:
                continue
            phases = "; ".join(f"{name} {s:.2f}" for name, s in row["phases"].items())
            kernels = "-"
            if "native_new" in row:
                kernels = (f"{row['native_new']} compiled, {row['native_cached']} cached, "
                           f"{row['numba_kernels']} by numba")
                if row.get("native_level0"):
                    kernels += f"; {row['native_level0']} at LLVM level 0"
                if row.get("background_wait", 0.0) >= 0.5:
                    kernels += f" (level 1 in the background: {row['background_wait']:.0f} s wall)"
            compiles = ", ".join(f"{k} {s:.1f}" for k, s in sorted(
                row.get("numba_compiles", {}).items()) if s >= 0.05) or "-"
            rows.append([case.label, VARIANT_TITLES[variant], phases, kernels, compiles,
                         f"{row['rss_mb']:.0f}"])
    return md_table(["case", "variant", "CPU s by phase", "kernel table",
                     "numba compiles (wall s)", "peak MB"], rows)


def library_table(libraries):
    rows = []
    for (method, kind, native), row in sorted(libraries.items(), key=lambda kv: str(kv[0])):
        what = "linearize_nonholonomic" if kind == "linearize" else method
        rows.append([what, "native" if native else "numba", seconds(row),
                     f"{row['rss_mb']:.0f}"])
    return md_table(["method", "kernels", "CPU s (warm-up model, empty caches)", "peak MB"], rows)


def judged_row(results, label, goal_case):
    """(variant, row) a goal is judged on."""
    by_variant = results.get(label, {})
    order = JUDGED["again"] if ("new process" in goal_case or "unchanged" in goal_case) \
        else JUDGED["default"]
    for variant in order:
        if variant in by_variant:
            return variant, by_variant[variant]
    return None, None


def _dominant(row):
    if not row or not row["phases"]:
        return ""
    name, s = max(row["phases"].items(), key=lambda kv: kv[1])
    return f"; most of it: {name} ({s:.1f} s)"


def goal_rows(goals, results):
    rows = []
    for goal_case, before, goal, limit, label in goals:
        variant, row = judged_row(results, label, goal_case)
        if row is None:
            rows.append([goal_case, before, goal, "-", "not measured", "case not in this run"])
            continue
        value = seconds(row)
        met = ok(row) and row["cpu"] <= limit
        why = f"{VARIANT_TITLES[variant]}, CPU s of the whole process{_dominant(row)}"
        compiles = {k: s for k, s in row.get("numba_compiles", {}).items() if s >= 0.05}
        if compiles:
            why += "; numba compiled " + ", ".join(f"{k} ({s:.1f} s wall)"
                                                   for k, s in sorted(compiles.items()))
        empty = results[label].get("empty")
        if variant != "empty" and empty is not None:
            why += f"; empty caches (the method's glue compiled too): {seconds(empty)}"
        old = results[label].get(f"{variant}, numba")
        if old is not None:
            why += f"; numba kernels: {seconds(old)}"
        rows.append([goal_case, before, goal, value, "**met**" if met else "**not met**", why])
    return rows


def memory_row(results):
    peaks = [(r["rss_mb"], f"{label} [{VARIANT_TITLES[v]}]") for label, by in results.items()
             if any(key in label for key in MEMORY_CASES) for v, r in by.items()]
    if not peaks:
        return ["peak memory of any generation or compile (humanoid, 12-link implicit)", "9.3 GB",
                "<= 2 GB", "-", "not measured", "no humanoid or 12-link case in this run"]
    peak, where = max(peaks)
    return ["peak memory of any generation or compile (humanoid, 12-link implicit)", "9.3 GB",
            "<= 2 GB", f"{peak:.0f} MB", "**met**" if peak <= MEMORY_GOAL_MB else "**not met**",
            f"largest peak resident memory of a child process: {where}"]


def _us(row, key):
    value = (row or {}).get(key)
    return "-" if value is None or not math.isfinite(value) else f"{value / 1e3:.3f}"


def percall_ratios(calls):
    """[(what, native / numba-compiled)] of the per-call row: the forward dynamics through a
    pointer, then each method's portable step."""
    out = []
    if calls and "fd_native_ns" in calls and "fd_numba_ns" in calls:
        out.append(("forward dynamics through a pointer",
                    calls["fd_native_ns"] / calls["fd_numba_ns"]))
    for method in ("rk4", "verlet"):
        a, b = (calls or {}).get(f"{method}_portable_native_ns"), \
            (calls or {}).get(f"{method}_portable_numba_ns")
        if a and b:
            out.append((f"portable {method} step", a / b))
    return out


def percall_row(calls):
    label = "cost per call once specialized (UR5 forward dynamics, 16-link steps)"
    ratios = percall_ratios(calls)
    if not ratios:
        return [label, "0.74 us; bench speed", "no regression", "-", "not measured",
                seconds(calls) if calls else "-"]
    worst = max(r for _, r in ratios)
    met = worst <= NOISE
    why = (f"native kernel / numba-compiled kernel, same process, alternating rounds: "
           f"{', '.join(f'{what} {r:.2f}x' for what, r in ratios)} (no regression: every ratio "
           f"<= {NOISE}); the specialized glue and a kernel called from Python are numba-compiled "
           f"as before: {calls.get('robot')} forward_dynamics from Python "
           f"{_us(calls, 'fd_python_unchecked_ns')} us without the argument check a call from "
           f"Python now makes (issue 34), {_us(calls, 'fd_python_ns')} us with it; 0.74 us in "
           f"reports/robots.md, before that check, on another day")
    return [label, "0.74 us; bench speed", "no regression",
            f"worst ratio {worst:.2f}x", "**met**" if met else "**not met**", why]


def percall_table(calls):
    if not calls:
        return ["(not measured)"]
    robot, n = calls.get("robot", "?"), calls.get("chain_n", "?")
    rows = [[f"{robot} forward_dynamics from Python (numba dispatcher, with the argument check "
             f"of a call from Python)", _us(calls, "fd_python_ns")],
            [f"{robot} forward_dynamics from Python without the argument check "
             f"(python_calls.unchecked, as accelerations calls it)",
             _us(calls, "fd_python_unchecked_ns")],
            [f"{robot} forward_dynamics in a jitted loop through its address: native kernel "
             f"(the portable glue's call)", _us(calls, "fd_native_ns")],
            [f"{robot} forward_dynamics in a jitted loop through its address: numba-compiled "
             f"kernel (the portable glue's call with $LAGRANGE_GEN_NATIVE=0)",
             _us(calls, "fd_numba_ns")],
            [f"{robot} forward_dynamics in a jitted loop, called directly (the specialized "
             f"glue's call)", _us(calls, "fd_direct_ns")]]
    for method in ("rk4", "verlet"):
        for key, what in (("specialized", "specialized glue"),
                          ("portable_native", "portable glue, native kernels"),
                          ("portable_numba", "portable glue, numba-compiled kernels")):
            rows.append([f"{n}-link pendulum, {method} step, {what}",
                         _us(calls, f"{method}_{key}_ns")])
    lines = md_table(["per call or step", "us"], rows)
    if not ok(calls):
        lines += ["", f"The per-call child did not finish: {seconds(calls)}"]
    return lines


def markdown(cases, results, libraries, calls, info):
    """The report's lines. info: command, numba, cpus, load, and the bench's settings: goals
    (firstrun.GOALS), first_steps, h, warmup_default (a stem), warmups {method: stem}."""
    FIRST_STEPS, GOALS, H = info["first_steps"], info["goals"], info["h"]
    load = info.get("load")
    load_text = f" (load average {load[0]:.1f} at the end)" if load else ""
    warmups = ", ".join(f"{m}: {stem}" for m, stem in info["warmups"].items())
    lines = [
        "# From model file to first step", "",
        f"`{info['command']}` (issue 40), numba {info['numba']}. Timings were taken on a loaded "
        f"{info['cpus']}-core machine shared with other jobs{load_text}: every number is CPU "
        f"seconds (user + system) of one fresh child process, from its start (interpreter and "
        f"imports included) to the end of its first call, not wall seconds.", "",
        f"Each child has its own NUMBA_CACHE_DIR, LAGRANGE_GEN_PORTABLE_DIR and generated folder, "
        f"LAGRANGE_GEN_INTERPRETED=0 (the first call runs compiled code, not the interpreted "
        f"tier), and simulate's default jit='auto'. Background compiles are on, as for a user: "
        f"a big kernel whose object at LLVM's level 1 is not cached runs at level 0 (the same "
        f"numbers, two to three times the time per call) while a detached process compiles "
        f"level 1 for the next run; that process's CPU is not the child's, and the next child "
        f"starts when it has ended. The first call: simulate from the model file (generated into an empty "
        f"folder) for {FIRST_STEPS} steps of h = {H:g}, or linearize_nonholonomic, or the "
        f"`lagrange-gen` command.", "",
        "- **empty caches**: the first model after an install (the method's portable glue is "
        "compiled too);",
        f"- **warm library**: the caches already hold the method's glue, compiled by a run of "
        f"the same method on another model ({info['warmup_default']}; {warmups}): what every new "
        f"model pays;",
        "- **again**: a new process on the warm-library run's caches and module: nothing new;",
        "- **numba kernels**: the same with $LAGRANGE_GEN_NATIVE=0 (the model's kernels compiled "
        "by numba, the path before native kernels); measured where affordable, a child is killed "
        "at its time limit ('> T s', with the phase it was in).", "",
        "## Model file to first step (CPU s)", "",
        *first_step_table(cases, results), "",
        "'loop': Trajectory.jit of the first call. Peak MB: the largest peak resident memory of "
        "the case's children.", "",
        "## Goals of issue 40", "",
        *md_table(["case", "before", "goal", "this run", "verdict", "why"],
                  goal_rows(GOALS, results) + [percall_row(calls), memory_row(results)]), "",
        "## Where the seconds go", "",
        "CPU seconds of each phase inside the child (the process total above also counts the "
        "interpreter's start). 'kernels' builds the portable kernel table: native kernels "
        "compiled by llvmlite or loaded from their object cache, or numba-compiled kernels; "
        "'first simulate' then compiles or loads the glue and runs. 'numba compiles': wall "
        "seconds of numba's outermost compiles in the child, by what they compile: the model's "
        "kernels (numba-compiled for a kernel table, or called from Python: the energy check, "
        "linearize), the glue and the stepper library, other.", "",
        *phase_table(cases, results), "",
        "## The method's glue (once per installation)", "",
        "The warm-up run that filled each warm library: a whole child on empty caches.", "",
        *library_table(libraries), "",
        "## Cost per call once compiled", "",
        "One child process, both kinds of kernel side by side, timed in alternating rounds (best "
        "of 7), so that the machine's load weighs on both alike; wall microseconds. From Python "
        "the generated module's forward_dynamics is the numba dispatcher; in a jitted loop the "
        "portable glue calls a kernel through its address (the native kernel, or with "
        "$LAGRANGE_GEN_NATIVE=0 the numba-compiled one), the specialized glue calls the "
        "numba-compiled kernel directly. Steps: the jitted loop's wall time per step; the "
        "portable glue with numba-compiled kernels runs on a second import of the same module "
        "(its own kernel table).", "",
        *percall_table(calls),
    ]
    return lines
