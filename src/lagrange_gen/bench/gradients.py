"""`lagrange-gen bench gradients`: the cost of forward sensitivities against the plain run, and
their agreement with central differences of simulate, written to reports/gradients.md.

Cost: the wall time of a run with k parameter sensitivities (and with q0, v0: 2n more columns)
over that of the same run without them, the best of a few repeats after a warm-up (compiles and
caches excluded), against the plain run's specialized loop (the production speed) and its
portable loop (the loop kind the sensitivity run uses: kernels through pointers).
Agreement: max over the saved rows of |S - central difference| / max |central difference| for
a parameter, at difference steps 1e-4 .. 1e-7: the difference quotient's error falls as eps^2
until the Newton tolerance over eps takes over.
"""

from __future__ import annotations

import platform
import tempfile
import time
from pathlib import Path

import numpy as np

#: (model file stem, build options, q0, v0, parameters in the order of k, label)
CASES = (("double_pendulum", {}, [0.5, 1.0], [0.0, 0.3], ["l2", "m2", "l1", "m1", "g"],
          "double pendulum (n = 2)"),
         ("spatial_chain", {"n": 4}, [0.3, -0.4, 0.5, 0.2], [0.2, 0.1, -0.3, 0.0], ["g"],
          "spatial chain, 4 bodies (graph kernels)"))
METHODS = ("explicit_euler", "symplectic_euler", "verlet", "midpoint", "implicit_euler", "rk4")


def _best(fn, repeats):
    """min over repeats of the run's own wall time (Trajectory.wall_time)."""
    return min(fn().wall_time for _ in range(repeats))


def _cost_rows(module, method, q0, v0, names, steps, repeats):
    import lagrange_gen as lg
    h = 1e-3
    t_end = steps * h

    def plain(jit):
        return lambda: lg.simulate(module, method, q0, v0, t_end=t_end, h=h, jit=jit,
                                   save_every=100)

    def sens(wanted):
        return lambda: lg.simulate(module, method, q0, v0, t_end=t_end, h=h, save_every=100,
                                   sensitivities=wanted)
    plain(None)()                   # warm-up: compiles the specialized and portable loops
    plain("portable")()
    specialized, portable = _best(plain("specialized"), repeats), _best(plain("portable"), repeats)
    rows = []
    ks = sorted({1, min(2, len(names)), len(names)})
    for wanted in [names[:k] for k in ks] + [["q0", "v0"]]:
        sens(wanted)()              # warm-up (the first use of a method compiles its loop)
        wall = _best(sens(wanted), repeats)
        k = len(q0) * 2 if wanted == ["q0", "v0"] else len(wanted)
        rows.append((", ".join(wanted), k, wall / steps * 1e6, wall / specialized, wall / portable,
                     1 + 0.5 * k))
    return specialized / steps * 1e6, portable / steps * 1e6, rows


def _agreement(module, method, q0, v0, name):
    import lagrange_gen as lg
    kw = dict(t_end=1.0, h=1e-2, save_every=10)
    S = lg.simulate(module, method, q0, v0, sensitivities=[name], **kw).sensitivity(name)
    value = float(module.DEFAULT_PARAMS[list(module.PARAMS).index(name)])
    out = []
    for eps in (1e-4, 1e-5, 1e-6, 1e-7):
        step = eps * max(1.0, abs(value))
        a = lg.simulate(module, method, q0, v0, params={name: value + step}, **kw)
        b = lg.simulate(module, method, q0, v0, params={name: value - step}, **kw)
        fd = (np.hstack((a.q, a.v)) - np.hstack((b.q, b.v))) / (2 * step)
        out.append(float(np.abs(S - fd).max() / np.abs(fd).max()))
    return out


def run_gradients_bench(models_dir, reports_dir, quick=False):
    """Measure, write reports_dir/gradients.md, return {"report": text}."""
    from ..codegen import generate_model
    from ..run.loader import import_generated
    steps, repeats = (2000, 2) if quick else (20000, 5)
    gen = Path(tempfile.mkdtemp(prefix="lagrange_gen_gradients_"))
    lines = ["# Forward sensitivities: cost and agreement", "",
             "Written by `lagrange-gen bench gradients`" + (" --quick" if quick else "") +
             f" ({platform.processor() or platform.machine()}, {time.strftime('%Y-%m-%d')}). "
             "Cost: wall time of a run with sensitivities over the same run without, best of "
             f"{repeats} after a warm-up, {steps} steps of h = 1e-3; goal (issue 42): at most "
             "1 + 0.5 k for k columns. The sensitivity run takes the portable loop (the kernels "
             "through pointers); ratios are given against the plain run's specialized loop "
             "(what simulate runs once compiled) and its portable loop.", ""]
    for stem, options, q0, v0, names, label in CASES:
        result = generate_model(Path(models_dir) / f"{stem}.py", gen, options=options,
                                sensitivities=True)
        module = import_generated(result.path)
        q0, v0 = np.array(q0), np.array(v0)
        lines += [f"## {label}", "",
                  "| method | plain us/step (specialized, portable) | with | k | us/step | "
                  "x specialized | x portable | goal 1 + 0.5 k |", "|---|---|---|---|---|---|---|---|"]
        for method in METHODS:
            spec_us, port_us, rows = _cost_rows(module, method, q0, v0, names, steps, repeats)
            for i, (wanted, k, us, xs, xp, goal) in enumerate(rows):
                plain = f"{spec_us:.2f}, {port_us:.2f}" if i == 0 else ""
                lines.append(f"| {method if i == 0 else ''} | {plain} | {wanted} | {k} | {us:.2f} | "
                             f"{xs:.2f} | {xp:.2f} | {goal:.1f} |")
        lines += ["", f"Agreement of d(q, v)/d {names[0]} with central differences of simulate "
                  "(t_end = 1, h = 1e-2), relative to the largest difference quotient, by "
                  "difference step:", "", "| method | 1e-4 | 1e-5 | 1e-6 | 1e-7 |",
                  "|---|---|---|---|---|"]
        for method in METHODS:
            errs = _agreement(module, method, q0, v0, names[0])
            lines.append(f"| {method} | " + " | ".join(f"{e:.1e}" for e in errs) + " |")
        lines.append("")
    text = "\n".join(lines)
    Path(reports_dir).mkdir(parents=True, exist_ok=True)
    (Path(reports_dir) / "gradients.md").write_text(text)
    return {"report": text}
