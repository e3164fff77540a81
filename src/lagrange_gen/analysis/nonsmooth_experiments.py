"""The lecture's nonsmooth experiments (HARD_CASES 9-11 and the Coulomb decay) as a report.

`lagrange-gen bench nonsmooth` runs them with the generated models and nonsmooth_euler, and
writes reports/nonsmooth.md with the measured numbers next to their references, and
reports/nonsmooth_cycles.png with the cycles in the (x, F) and (x, F - m x'') planes.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..nonsmooth.play import loop_area, play_operator


def restoring_force(t, v, h, F, m, c):
    """R_{n+1} = F_{n+1} - m (v_{n+1} - v_n)/h - c v_{n+1} (S-1,) from saved states at every step:
    the force implicit Euler balances against k0 x + sum k_i u_i."""
    return F[1:] - m * np.diff(v) / h - c * v[1:]


def last_loading_branch(x, v):
    """(indices, x_turn): the last complete loading half-cycle, from a minimum of x to the next
    maximum (x, v of shape (S,))."""
    turns_up = np.where((v[:-1] < 0) & (v[1:] >= 0))[0]
    if len(turns_up) == 0:
        raise ValueError("no loading half-cycle: x never turns from decreasing to increasing")
    start = (turns_up[-2] if len(turns_up) > 1 else turns_up[-1]) + 1
    stop = start + int(np.argmax(v[start:] < 0))
    return np.arange(start, stop), float(x[start])


def branch_slopes(x, r, windows):
    """Least-squares slopes and intercepts of r(x) (N,) on each x-window [(lo, hi), ...], and the
    breakpoints where consecutive lines meet."""
    lines = []
    for lo, hi in windows:
        sel = (x > lo) & (x < hi)
        lines.append(np.polyfit(x[sel], r[sel], 1))
    breaks = [(b2 - b1) / (a1 - a2) for (a1, b1), (a2, b2) in zip(lines, lines[1:])]
    return [a for a, _ in lines], breaks


def _case10(simulate, models):
    traj = simulate(models / "generalized_prandtl.py", method="implicit_euler", t_end=400.0, h=1e-2)
    P = traj.params
    F = P["f"] * np.cos(P["omega"] * traj.t)
    R = restoring_force(traj.t, traj.v[:, 0], traj.h, F, P["m"], P["c"])
    idx, x_turn = last_loading_branch(traj.q[:, 0], traj.v[:, 0])
    idx = idx[idx > 0]
    xb, rb = traj.q[idx, 0] - x_turn, R[idx - 1]
    slopes, breaks = branch_slopes(xb, rb, [(0.2, 1.8), (2.2, 3.8), (4.2, 5.8), (6.2, xb.max() - 0.1)])
    return traj, F, R, slopes, breaks


def _coulomb(simulate, models):
    h = 1e-4
    traj = simulate(models / "coulomb_oscillator.py", method="implicit_euler", q0=[1.05],
                    t_end=7 * np.pi, h=h, save_every=10)
    turns = []
    for j in range(1, 6):
        i = int(round(j * np.pi / (h * 10)))
        window = traj.q[max(i - 20, 0):i + 20, 0]
        turns.append(float(window[np.argmax(np.abs(window))]))
    return turns, float(traj.q[-1, 0])


def _case9(simulate, models):
    out = {}
    for name in ("prandtl", "prandtl_hardening"):
        traj = simulate(models / f"{name}.py", method="implicit_euler", t_end=300.0, h=1e-3, save_every=10)
        out[name] = traj
    return out


def _figure(path, case9, case10):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    traj, F, R, *_ = case10
    fig, axes = plt.subplots(2, 2, figsize=(10, 8))
    steady = traj.t > 150
    axes[0, 0].plot(traj.q[steady, 0], F[steady], lw=0.8)
    axes[0, 0].set(title="generalized Prandtl: (x, F)", xlabel="x", ylabel="F")
    axes[0, 1].plot(traj.q[1:, 0][steady[1:]], R[steady[1:]] + traj.params["c"] * traj.v[1:, 0][steady[1:]], lw=0.8)
    axes[0, 1].set(title="(x, F - m x'')", xlabel="x", ylabel="F - m x''")
    for name, traj9 in case9.items():
        axes[1, 0].plot(traj9.t, traj9.q[:, 0], lw=0.8, label=name)
    axes[1, 0].set(title="Prandtl models, F = 2 cos(0.1 t)", xlabel="t", ylabel="x", yscale="symlog")
    axes[1, 0].legend()
    s = np.concatenate([np.arange(0, 301), 300 - np.arange(1, 601), -300 + np.arange(1, 601)]) * 0.01
    axes[1, 1].plot(s, 2.0 * play_operator(s, 1.0))
    axes[1, 1].set(title="play operator, k = 2, eta = 1", xlabel="s", ylabel="k u")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def run_nonsmooth_report(report_dir="reports", models_dir="models"):
    """Run the experiments and write reports/nonsmooth.md and reports/nonsmooth_cycles.png."""
    from ..run.simulate import simulate
    models = Path(models_dir)
    report_dir = Path(report_dir)
    report_dir.mkdir(parents=True, exist_ok=True)
    case10 = _case10(simulate, models)
    _, _, _, slopes, breaks = case10
    turns, rest = _coulomb(simulate, models)
    case9 = _case9(simulate, models)
    s = np.concatenate([np.arange(0, 301), 300 - np.arange(1, 601), -300 + np.arange(1, 601)]) * 0.01
    area = abs(loop_area(s[300:], 2.0 * play_operator(s, 1.0)[300:]))
    _figure(report_dir / "nonsmooth_cycles.png", case9, case10)
    x0, x1 = case9["prandtl"].q[:, 0], case9["prandtl_hardening"].q[:, 0]
    lines = [
        "# Nonsmooth experiments (Lamarque's lecture, HARD_CASES 9-11)", "",
        "`lagrange-gen bench nonsmooth`: generated models, `simulate(method='implicit_euler')` "
        "(nonsmooth_euler: exact Saint-Venant return map, Moreau-Jean friction).", "",
        "| case | quantity | measured | reference |", "|---|---|---|---|",
        f"| 10 generalized Prandtl, h = 1e-2 | loading slopes | {', '.join(f'{a:.10f}' for a in slopes)} | 4/3, 1, 2/3, 1/3 |",
        f"| 10 | breakpoints from the turn | {', '.join(f'{b:.4f}' for b in breaks)} | 2, 4, 6 |",
        f"| 11 play operator k = 2, eta = 1 | loop area | {area:.12f} | 16 |",
        f"| Coulomb decay, h = 1e-4 | turning points at t = j pi | {', '.join(f'{x:+.4f}' for x in turns)} | -0.85, +0.65, -0.45, +0.25, -0.05 |",
        f"| Coulomb decay | rest position | {rest:+.4f} | -0.05 |",
        f"| 9 Prandtl k0 = 0, h = 1e-3 | peak-to-peak x over 300 s | {np.ptp(x0):.1f} | order 2 f/(m w^2) = 400 |",
        f"| 9 Prandtl k0 = 1 | max abs x after t = 100 | {np.abs(x1[case9['prandtl_hardening'].t > 100]).max():.3f} | 2.02 - k eta / k0 = 1.02 |",
        "", "![cycles](nonsmooth_cycles.png)", "",
    ]
    (report_dir / "nonsmooth.md").write_text("\n".join(lines))
    return report_dir / "nonsmooth.md"
