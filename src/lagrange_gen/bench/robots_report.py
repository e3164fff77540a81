"""Markdown of `lagrange-gen bench robots` (bench/robots.py): one table row per robot (stage
seconds, size, agreement with Pinocchio, per-call and per-step costs against Pinocchio) and the
goals of issue 28, each marked met / not met from this run's numbers."""

from __future__ import annotations

#: the stepping methods measured per robot
METHODS = ("rk4", "implicit_euler")
#: issue 28's goals: generate + compile + first step (s)
GOAL_TOTAL_S = {"spatial chain, 8 links": 15.0, "spatial chain, 12 links": 30.0,
                "humanoid tree, 30 DoF": 120.0}
GOAL_ACCEL_RATIO = 1.5          # mod.accelerations against pin.aba

#: the stages of "generate + compile + first step": the first rk4 step compiles what rk4 needs
STAGES = ("model_file", "derive", "emit", "first_step")


def _s(row, key, fmt="{:.1f}"):
    value = row.get(key)
    return "-" if value is None else fmt.format(value)


def _us(row, key):
    value = row.get(key)
    return "-" if value is None else f"{value / 1e3:.2f}"


def total(row):
    """model file + derive + emit + first rk4 step (with its compile), or None when unfinished."""
    if any(row.get(k) is None for k in STAGES):
        return None
    return sum(row[k] for k in STAGES)


def cold_total(row):
    """total() with the stepper library's rk4 glue compile added (a first model on a fresh
    installation), or None."""
    t = total(row)
    return None if t is None or row.get("library_compile") is None else t + row["library_compile"]


def _status(row):
    if row.get("timeout"):
        return f"timeout after {row['limit']:.0f} s (in {row['where']})"
    if row.get("error"):
        return f"failed in {row['where']}: {row['error']}"
    return "done"


def _agreement(row):
    keys = ("err_H", "err_qdd", "err_dq", "err_dv")
    if any(row.get(k) is None for k in keys):
        return "-"
    return " / ".join(f"{row[k]:.0e}" for k in keys)


def _met(ok):
    return "-" if ok is None else ("**met**" if ok else "**not met**")


def _by_label(rows):
    return {r["label"]: r for r in rows}


def goal_rows(rows):
    """[work, this run, goal, met] of issue 28's table, from the rows of this run."""
    by, out = _by_label(rows), []
    for label, goal in GOAL_TOTAL_S.items():
        row = by.get(label)
        if row is None:
            out.append([f"{label}: generate + compile + first step", "not in this run", f"<= {goal:.0f} s", "-"])
            continue
        t = total(row)
        now = f"{t:.1f} s" if t is not None else _status(row)
        out.append([f"{label}: generate + compile + first step", now, f"<= {goal:.0f} s",
                    _met(t is not None and t <= goal)])
    chains = sorted((r for r in rows if r["stem"] == "spatial_chain" and r.get("lines")), key=lambda r: r["n"])
    if len(chains) >= 2:
        a, b = chains[0], chains[-1]
        exponent = __import__("math").log(b["lines"] / a["lines"]) / __import__("math").log(b["n"] / a["n"])
        out.append([f"generated lines against n (chains {a['n']} -> {b['n']} links)",
                    f"{a['lines']} -> {b['lines']} lines: ~n^{exponent:.1f}", "at most ~n^2",
                    _met(exponent <= 2.2)])
    else:
        out.append(["generated lines against n", "fewer than two chain sizes finished", "at most ~n^2", "-"])
    ur5 = by.get("UR5")
    if ur5 and ur5.get("fd_ns"):
        out.append(["UR5 forward dynamics per call from Python",
                    f"{ur5['fd_ns'] / 1e3:.2f} us vs pin.aba {ur5['pin_aba_ns'] / 1e3:.2f} us",
                    "faster than pin.aba", _met(ur5["fd_ns"] < ur5["pin_aba_ns"])])
        ratio = ur5["accel_ns"] / ur5["pin_aba_ns"]
        out.append(["UR5 `mod.accelerations` per call", f"{ur5['accel_ns'] / 1e3:.2f} us ({ratio:.1f}x pin.aba)",
                    f"<= {GOAL_ACCEL_RATIO}x pin.aba", _met(ratio <= GOAL_ACCEL_RATIO)])
    else:
        out.append(["UR5 forward dynamics per call from Python", "not measured", "faster than pin.aba", "-"])
    c12 = by.get("spatial chain, 12 links")
    if c12 and c12.get("fd_ns"):
        out.append(["12-link forward dynamics per call from Python",
                    f"{c12['fd_ns'] / 1e3:.2f} us vs pin.aba {c12['pin_aba_ns'] / 1e3:.2f} us",
                    "faster than pin.aba", _met(c12["fd_ns"] < c12["pin_aba_ns"])])
        out.append(["12-link d(qdd)/d(q, qd) per call",
                    f"{c12['dqdd_jit_ns'] / 1e3:.2f} us (forward_dynamics_jacobian) vs "
                    f"pin.computeABADerivatives {c12['pin_daba_ns'] / 1e3:.2f} us",
                    "faster than pin.computeABADerivatives", _met(c12["dqdd_jit_ns"] < c12["pin_daba_ns"])])
    else:
        why = _status(c12) if c12 else "not in this run"
        out.append(["12-link forward dynamics per call from Python", why, "faster than pin.aba",
                    "**not met**" if c12 else "-"])
        out.append(["12-link d(qdd)/d(q, qd) per call", why, "faster than pin.computeABADerivatives",
                    "**not met**" if c12 else "-"])
    out.append(["planar cart pendulum and 16-link chain per step", "not measured here (`bench speed`)",
                "no regression", "-"])
    return out


def markdown(rows, quick=False):
    lines = ["# Robots: 3D trees against Pinocchio", "",
             "`lagrange-gen bench robots`" + (" --quick" if quick else "") +
             " (issue 28), one run on a shared machine: compare ratios within the run. Each robot "
             "in its own process with a fresh numba cache and a time limit; modules generated with "
             f"`--methods {','.join(METHODS)}` (rk4, and the Jacobian kernels the derivative rows "
             "need). Pinocchio builds each robot from the same joint table (TREE).", "",
             "## Pipeline", "",
             "The first rk4 step compiles the kernels rk4 and the energy check reach; the stepper "
             "library's rk4 glue is compiled into the case's fresh cache just before, by another "
             "process (it is paid once per installation, by the first model a user runs): its "
             "seconds are the 'stepper library' column, and 'total, cold library' adds them.", "",
             "| robot | n | model file s | derive s | emit s | first rk4 step s (with its compile) | "
             "total s | stepper library s | total, cold library s | other kernels' compile s | lines | KB | status |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        t = total(r)
        lines.append(f"| {r['label']} | {r.get('n', '-')} | {_s(r, 'model_file')} | {_s(r, 'derive')} | "
                     f"{_s(r, 'emit')} | {_s(r, 'first_step')} | "
                     f"{'-' if t is None else f'{t:.1f}'} | {_s(r, 'library_compile')} | "
                     f"{_s({'t': cold_total(r)}, 't')} | "
                     f"{_s(r, 'kernel_compile')} | {r.get('lines', '-')} | {_s(r, 'kb', '{:.0f}')} | "
                     f"{_status(r)} |")
    lines += ["", "## Against Pinocchio", "",
              "Agreement: max relative difference of H (crba), qdd (aba), d(qdd)/dq and d(qdd)/dqd "
              "(computeABADerivatives) at one random state. Per call from Python, best of 5, in us. "
              "d(qdd)/d(q, qd): 'py' composes it in Python from dynamics, rhs_jacobian and "
              "mass_matvec_dq with numpy solves; 'kernel' is the module's forward_dynamics_jacobian. "
              "Inverse dynamics: the module's inverse_dynamics against pin.rnea. "
              "rk4: us per step in our jitted loop; Pinocchio's column is a "
              "Python loop over pin.aba (it has no jitted loop), for scale only.", "",
              "| robot | agreement H / qdd / dq / dv | forward_dynamics | mod.accelerations | pin.aba | "
              "d(qdd) py | d(qdd) kernel | pin.computeABADerivatives | inverse_dynamics | pin.rnea | "
              "rk4 step | pin rk4 (Python loop) |",
              "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['label']} | {_agreement(r)} | {_us(r, 'fd_ns')} | {_us(r, 'accel_ns')} | "
                     f"{_us(r, 'pin_aba_ns')} | {_us(r, 'dqdd_py_ns')} | {_us(r, 'dqdd_jit_ns')} | "
                     f"{_us(r, 'pin_daba_ns')} | {_us(r, 'id_ns')} | {_us(r, 'pin_rnea_ns')} | "
                     f"{_us(r, 'rk4_ns')} | {_us(r, 'pin_rk4_py_ns')} |")
    lines += ["", "## Goals of issue 28", "", "| work | this run | goal | |", "|---|---|---|---|"]
    lines += [f"| {' | '.join(cells)} |" for cells in goal_rows(rows)]
    lines += ["", "A module generated from bodies has inverse_dynamics, gravity_forces, bias_forces, "
              "forward_dynamics_torques and forward_dynamics_jacobian (README, Robots)."]
    if quick:
        lines += ["", "`--quick`: the UR5 and 3- and 4-link chains only; the goals' robots are not in "
                  "this run."]
    return lines
