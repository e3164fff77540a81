"""Markdown of `lagrange-gen bench speed` (bench/speed.py): the headline table (each row: the
number of this run, the issue's goal, met or not) and the details behind it."""

from __future__ import annotations

#: The goals each row is judged against: a warm start beyond the imports (s), the speed-up over
#: PyDy at equal error, our step time over a hand-written loop, MuJoCo's RK4 over ours.
WARM_GOAL_S, PEER_GOAL, HAND_GOAL, MUJOCO_RK4_GOAL = 0.5, 100.0, 1.5, 3.0
#: Microseconds a warm lg.simulate call may cost beyond its stepping (small model).
CALL_GOAL_US = 50.0

PYDY = "PyDy + scipy DOP853"


def _met(ok):
    return "-" if ok is None else ("met" if ok else "not met")


def _fastest(times):
    """(method, seconds) of the fastest method that reached the target, or (None, None)."""
    reached = {m: t for m, t in times.items() if t is not None}
    if not reached:
        return None, None
    best = min(reached, key=reached.get)
    return best, reached[best]


def _precision_row(res):
    method, ours = _fastest(res["ours"])
    pydy = res["peers"].get(PYDY)
    work = "cart pendulum, wall time to final-state error 1e-8, against PyDy + scipy DOP853"
    if res["pydy"] is None:
        return [work, "PyDy not installed: not measured", ">= 100x", "-"]
    if ours is None or pydy is None:
        return [work, f"target not reached (ours {method}, PyDy {pydy})", ">= 100x", "-"]
    ratio = pydy / ours
    return [work, f"{ratio:.0f}x faster ({method} {ours * 1e3:.2f} ms, PyDy "
                  f"({res['pydy']}) {pydy * 1e3:.1f} ms)", f">= {PEER_GOAL:.0f}x",
            _met(ratio >= PEER_GOAL)]


def _whole_call_row(res):
    """dop853's whole lg.simulate call at error 1e-8 against PyDy's whole solve_ivp call."""
    work = ("cart pendulum, the whole lg.simulate call (checks, set-up, run, Trajectory) at "
            "final error 1e-8, against PyDy + scipy DOP853's whole solve_ivp call")
    whole = res.get("whole")
    if whole is None:
        return [work, "dop853 did not reach the target: not measured", ">= 100x", "-"]
    ours = (f"dop853 rtol {whole['rtol']:.0e}: {whole['call'] * 1e3:.2f} ms whole "
            f"({whole['run'] * 1e3:.2f} ms the jitted run)")
    if whole["pydy"] is None:
        return [work, f"{ours}; PyDy not installed (pip install 'lagrange-gen[peers]'): "
                      f"not compared", ">= 100x", "-"]
    ratio = whole["pydy"] / whole["call"]
    return [work, f"{ratio:.0f}x faster ({ours}; PyDy rtol {whole['pydy_rtol']:.0e} "
                  f"{whole['pydy'] * 1e3:.1f} ms)", f">= {PEER_GOAL:.0f}x",
            _met(ratio >= PEER_GOAL)]


def _call_rows(calls):
    """One row per warm call of bench/speed.py CALLS: microseconds beyond the stepping."""
    return [[f"warm lg.simulate call, cart pendulum, {r['label']}: cost beyond the stepping",
             f"{r['beyond']:.0f} us (whole call {r['whole']:.0f} us, stepping "
             f"{r['stepping']:.0f} us)", f"<= {CALL_GOAL_US:.0f} us",
             _met(r["beyond"] <= CALL_GOAL_US)] for r in calls]


def _hand_row(steps):
    ratios = {r["method"]: r["ours_ns"] / r["hand_ns"] for r in steps}
    text = ", ".join(f"{m} {x:.1f}x" for m, x in ratios.items()) + " slower"
    return ["cart pendulum, ns per step against a closed-form hand-written numba loop",
            text, f"<= {HAND_GOAL}x for every method that has a hand version",
            _met(all(x <= HAND_GOAL for x in ratios.values()))]


def _chain_rows(chain, n_links):
    ours, theirs = chain["ours"], chain["mujoco"]
    se, vv, rk = (ours[m] / 1e3 for m in ("symplectic_euler", "verlet", "rk4"))
    if theirs is None:
        return [[f"{n_links}-link chain against MuJoCo", f"mujoco not installed: not measured "
                 f"(ours: symplectic_euler {se:.1f} us, verlet {vv:.1f} us, rk4 {rk:.1f} us)",
                 "-", "-"]]
    euler, rk4 = theirs["Euler"]["c_loop"] / 1e3, theirs["RK4"]["c_loop"] / 1e3
    return [[f"{n_links}-link chain, ns per step against MuJoCo's Euler ({euler:.1f} us)",
             f"symplectic_euler {se:.1f} us, verlet {vv:.1f} us",
             "both faster than MuJoCo Euler", _met(se < euler and vv < euler)],
            [f"{n_links}-link chain, rk4 against MuJoCo's RK4 ({rk4:.1f} us)",
             f"{rk:.1f} us ({rk4 / rk:.1f}x faster)" if rk < rk4 else
             f"{rk:.1f} us ({rk / rk4:.1f}x slower)", f"keep >= {MUJOCO_RK4_GOAL:.0f}x",
             _met(rk4 / rk >= MUJOCO_RK4_GOAL)]]


def _cold_rows(cold):
    """One row per cold case: derive + generate + load + compile + first steps on a clean
    machine (empty numba cache and portable directory), judged against the goal; the model
    just written (the stepper library cached by an earlier model) beside it."""
    return [[f"first simulate on a clean machine (empty caches), beyond imports: {r['label']}",
             f"{r['total']:.1f} s (a model just written, the stepper cached: "
             f"{r['library_cached']:.1f} s)", f"<= {r['goal']:.0f} s",
             f"{_met(r['total'] <= r['goal'])} (model just written: "
             f"{_met(r['library_cached'] <= r['goal'])})"] for r in cold]


def _warm_row(warm):
    beyond = warm["module_import"] + warm["first_step"]
    return ["warm cache, new process to the first step (beyond imports)",
            f"{beyond:.2f} s (total wall {warm['wall']:.2f} s with the interpreter)",
            f"keep < {WARM_GOAL_S} s", _met(beyond < WARM_GOAL_S)]


def markdown(results):
    """Lines of reports/speed.md."""
    rows = [_precision_row(results["precision"]), _whole_call_row(results["precision"]),
            *_call_rows(results["calls"]), _hand_row(results["steps"]),
            *_chain_rows(results["chain"], results["chain_n"]), *_cold_rows(results["cold"]),
            _warm_row(results["warm"])]
    quick = " --quick" if results["quick"] else ""
    lines = ["# Speed", "",
             f"`lagrange-gen bench speed{quick}`: every row measured in this one run on a shared "
             f"2-core machine; compare the ratios, not the absolute times.", "",
             "| work | this run | goal | |", "|---|---|---|---|"]
    lines += ["| " + " | ".join(r) + " |" for r in rows]
    return lines + ["", *_precision_details(results["precision"], results["case"]),
                    *_call_details(results["calls"], results["precision"].get("whole")),
                    *_step_details(results["steps"]), *_chain_details(results["chain"], results["chain_n"]),
                    *_cold_details(results["cold"], results["warm"])]


def _ms(t):
    return "not reached" if t is None else f"{t * 1e3:.2f} ms"


def _precision_details(res, case):
    lines = ["## Wall time to final-state error 1e-8", "",
             f"{case.stem}, T = {case.t_end:g}, q0 = {case.q0}, v0 = {case.v0} (sweeps and "
             f"interpolation of bench/precision.py; dop853 over rtol).",
             "PyDy: " + (f"installed, {res['pydy']} right-hand side." if res["pydy"] else
                         "not installed (pip install 'lagrange-gen[peers]')."), "",
             "| method | wall time to 1e-8 |", "|---|---|"]
    lines += [f"| {m} | {_ms(t)} |" for m, t in res["ours"].items()]
    lines += [f"| {name} | {_ms(t)} |" for name, t in res["peers"].items()]
    return lines + [""]


def _call_details(calls, whole):
    lines = ["## The cost of one call (microseconds, medians of warm calls)", "",
             "The whole `lg.simulate(mod, method, q0, v0, ...)` call timed around it, against "
             "its stepping (Trajectory.wall_time: the jitted run and the chunk loop around it); "
             "the phases are timed in a second pass by wrapping the functions simulate calls "
             "(bench/speed.py call_breakdown; the wrappers add about a microsecond each, so "
             "the first three columns come from calls without them), each a median over the "
             "calls: the output buffers, the driver less the stepping, the Trajectory less the "
             "energy check, the energy check, the inputs and outputs; checks and set-up are "
             "the wrapped call less the stepping and all of these.", "",
             "| call | glue | whole call | stepping | beyond the stepping | checks and set-up | "
             "buffers | driver (less stepping) | Trajectory | energy check | inputs, outputs |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    lines += [f"| {r['label']} | {r['jit']} | {r['whole']:.0f} | {r['stepping']:.0f} | "
              f"{r['beyond']:.0f} | {r['checks']:.0f} | {r['buffers']:.0f} | "
              f"{r['driver']:.0f} | {r['trajectory']:.0f} | {r['energy']:.0f} | "
              f"{r['io']:.0f} |" for r in calls]
    if whole is not None:
        lines += ["", f"dop853 at rtol {whole['rtol']:.0e} (final error {whole['final']:.2g}): "
                      f"whole call {whole['call'] * 1e3:.3f} ms, jitted run "
                      f"{whole['run'] * 1e3:.3f} ms"
                      + ("" if whole["pydy"] is None else
                         f"; PyDy + scipy DOP853 at rtol {whole['pydy_rtol']:.0e} (final error "
                         f"{whole['pydy_final']:.2g}): {whole['pydy'] * 1e3:.2f} ms per "
                         f"solve_ivp call") + "."]
    return lines + [""]


def _step_details(steps):
    lines = ["## ns per step against the hand-written loops (bench/steppers.py)", "",
             "| method | library | hand, closed form | ratio | Newton it./step | portable loop |",
             "|---|---|---|---|---|---|"]
    lines += [f"| {r['method']} | {r['ours_ns']:.0f} | {r['hand_ns']:.0f} | "
              f"{r['ours_ns'] / r['hand_ns']:.2f} | {r['iters']:.2f} | "
              f"{r['portable_ns']:.0f} ({r['portable_ns'] / r['ours_ns']:.2f}x) |" for r in steps]
    return lines + ["", "The library column is the specialized loop (the generated module's "
                        "run_<method>); the portable loop (lagrange_gen.jit.portable, what a model "
                        "just written runs first) is timed the same way.", ""]


def _chain_details(chain, n_links):
    lines = [f"## {n_links}-link chain, ns per step", ""]
    lines += [f"- ours {m}: {ns:.0f} ns (portable loop: {chain['portable'][m]:.0f} ns)"
              for m, ns in chain["ours"].items()]
    if chain["mujoco"] is None:
        return lines + ["- MuJoCo: not installed (pip install 'lagrange-gen[peers]').", ""]
    lines += [f"- MuJoCo {name}: {t['c_loop']:.0f} ns in a C loop (mujoco.rollout), "
              f"{t['python_loop']:.0f} ns per mj_step from a Python loop"
              for name, t in chain["mujoco"].items()]
    return lines + [f"- the MJCF chain is the model's chain: MuJoCo RK4 and our rk4 agree to "
                    f"{chain['equivalence']:.1g} after 1000 steps of 1 ms.", ""]


def _cold_details(cold, warm):
    lines = ["## First simulate of a model just written (seconds)", "",
             "New process, model generated into a fresh directory, 10 steps of 1 ms, "
             "simulate's default jit=\"auto\" (lagrange_gen.jit.portable). \"Model just written\": "
             "a numba cache in which another model (bench/speed.py WARMUP_STEM) already ran the "
             "method, so the portable stepper is cached and nothing of this model is; what "
             "every new model but the first after an install costs. \"Everything cold\": a "
             "fresh NUMBA_CACHE_DIR and LAGRANGE_GEN_PORTABLE_DIR (a clean machine), the portable stepper compiled too (once per method and "
             "library version). \"Specialized\": everything cold with jit=\"specialized\", "
             "the model's own stepper compiled (what every new model cost before the portable "
             "glue).", "",
             "| model, method | derive + generate | load, compile, first steps | model just "
             "written | loop | everything cold | of which numba compiling kernels / stepper "
             "/ other | specialized, everything cold | goal |",
             "|---|---|---|---|---|---|---|---|---|"]
    lines += [f"| {r['label']} | {r['library_generate']:.2f} | "
              f"{r['library_cached'] - r['library_generate']:.2f} | {r['library_cached']:.2f} | "
              f"{r['library_jit']} | {r['total']:.2f} | {r['compiles']['kernels']:.2f} / "
              f"{r['compiles']['stepper']:.2f} / {r['compiles']['other']:.2f} | "
              f"{r['specialized']:.2f} | <= {r['goal']:.0f} |" for r in cold]
    return lines + ["", f"Warm cache (cart pendulum, rk4): interpreter + numpy/numba imports "
                        f"{warm['imports']:.2f} s, module import {warm['module_import']:.2f} s, "
                        f"run_rk4 load + first step {warm['first_step']:.3f} s.", ""]
