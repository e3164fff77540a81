"""The figure of a Trajectory (and of an EnsembleResult: plot_ensemble): what a run did, one
quantity per axis.

Left column the coordinates, right column their velocities, one row per coordinate (an angle that
winds up to 35 rad no longer flattens the others); below, panels for what the run has: the energy
error E - E0 (or the energy balance E - E0 - W when the trajectory carries the work W of the
non-conservative forces), |Phi| and |J v| and the multipliers of a constrained run, the element
states of a nonsmooth run. An adaptive run (dop853, dop853_impacts) saves a row per step, and its
steps are long where the motion is smooth (a free flight of the bouncing ball is one or two
steps): its coordinates and velocities are drawn along each step as the cubic Hermite curve
through (q, v) at the step's ends (``state_curve``), not as chords; the rows a switch writes
twice (before and after an impact) draw the jump at its time. Built on matplotlib.figure.Figure
(no pyplot, no backend switch), so it also works inside a notebook, where the returned Figure
displays itself.
"""

from __future__ import annotations

import numpy as np

# above this many coordinates, all coordinates share one axis (and all velocities another)
MAX_ROWS = 8
_ROW_HEIGHT = 1.6
# an adaptive run's curve has about this many points over its time span, plus its rows
CURVE_POINTS = 2000
# an ensemble's figure draws at most this many members, and labels them when at most MAX_LEGEND
MAX_MEMBERS = 50
MAX_LEGEND = 8


def plot_trajectory(traj, path=None):
    """The Figure of ``traj`` (see the module docstring); with ``path`` it is written there
    (format from the suffix) and None returned."""
    from matplotlib.figure import Figure
    panels = _panels(traj)
    n = len(traj.coords)
    state_rows = n if n <= MAX_ROWS else 1
    rows = state_rows + (len(panels) + 1) // 2
    fig = Figure(figsize=(10, 1.2 + _ROW_HEIGHT * rows), layout="constrained")
    grid = fig.add_gridspec(rows, 2)
    first = None
    t, q, v = state_curve(traj)
    for r in range(state_rows):
        which = [r] if n <= MAX_ROWS else list(range(n))
        for col, (values, suffix) in enumerate(((q, ""), (v, "_dot"))):
            ax = fig.add_subplot(grid[r, col], sharex=first)
            first = first or ax
            for i in which:
                ax.plot(t, values[:, i], lw=1, label=traj.coords[i] + suffix)
            ax.set_ylabel(traj.coords[which[0]] + suffix if len(which) == 1 else
                          ("q" if col == 0 else "v"))
            if len(which) > 1:
                ax.legend(loc="upper right", fontsize="small", ncol=2)
    bottom = fig.axes[-2:]
    for k, (label, draw) in enumerate(panels):
        ax = fig.add_subplot(grid[state_rows + k // 2, k % 2], sharex=first)
        draw(ax)
        ax.set_ylabel(label)
        bottom[k % 2] = ax
    for ax in fig.axes:
        ax.tick_params(labelsize="small")
    for ax in bottom:
        ax.set_xlabel("t")
    fig.suptitle(f"{traj.model}: {traj.method}, {_steps(traj)}")
    return _written(fig, path)


def _written(fig, path):
    """``fig``, or None after writing it to ``path`` (format from the suffix)."""
    if path is None:
        return fig
    from pathlib import Path
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    return None


def plot_ensemble(result, path=None, members=None):
    """The Figure of an EnsembleResult: one row per coordinate (the first MAX_ROWS), q left and
    v right, one line per drawn member; below, each member's E - E0. ``members``: indices to
    draw (default every member, or MAX_MEMBERS evenly spread); with at most MAX_LEGEND drawn,
    each line is labelled by its member's parameters ("k=10, m=0.5", those that vary). Rows
    after a member's failure are NaN and leave its line short. With ``path`` the figure is
    written there and None returned."""
    from matplotlib.figure import Figure
    M = len(result.q)
    if members is None:
        members = np.unique(np.linspace(0, M - 1, min(M, MAX_MEMBERS)).round().astype(int))
    members = [int(i) for i in members]
    labels = _member_labels(result, members)
    n = len(result.coords)
    shown = min(n, MAX_ROWS)
    fig = Figure(figsize=(10, 1.2 + _ROW_HEIGHT * (shown + 1)), layout="constrained")
    grid = fig.add_gridspec(shown + 1, 2)
    first = None
    for i in range(shown):
        for col, (values, suffix) in enumerate(((result.q, ""), (result.v, "_dot"))):
            ax = fig.add_subplot(grid[i, col], sharex=first)
            first = first or ax
            for member, label in zip(members, labels):
                ax.plot(result.t, values[member, :, i], lw=0.8, label=label)
            ax.set_ylabel(result.coords[i] + suffix)
            ax.tick_params(labelsize="small")
    ax = fig.add_subplot(grid[shown, :], sharex=first)
    for member, label in zip(members, labels):
        ax.plot(result.t, result.energy[member] - result.energy[member, 0], lw=0.8, label=label)
    ax.set_ylabel("E - E0")
    ax.set_xlabel("t")
    ax.tick_params(labelsize="small")
    if len(members) <= MAX_LEGEND:
        ax.legend(loc="upper right", fontsize="small", ncol=2)
    what = f"{len(members)} of {M} members" if len(members) < M else f"{M} members"
    coords = f", first {shown} of {n} coordinates" if shown < n else ""
    failed = int(np.count_nonzero(~result.ok))
    fig.suptitle(f"{result.model}: {result.method}, h = {result.h:g}, {what}{coords}"
                 + (f" ({failed} failed)" if failed else ""))
    return _written(fig, path)


def _member_labels(result, members):
    """One label per drawn member: its parameters that vary across the ensemble ("k=10"), or
    "member i" when none vary."""
    varying = [j for j in range(result.params.shape[1])
               if np.ptp(result.params[:, j]) > 0] if len(result.params) else []
    if not varying:
        return [f"member {i}" for i in members]
    return [", ".join(f"{result.param_names[j]}={result.params[i, j]:g}" for j in varying)
            for i in members]


def state_curve(traj, points=CURVE_POINTS):
    """(t (K,), q (K, n), v (K, n)): what the state axes draw. A fixed-step run: its rows. An
    adaptive run (traj.step_counts): its rows, and between two rows about ``points`` * (their
    time apart) / (the run's time span) points of the cubic Hermite q(t) through (q, v) at both
    rows, with v = dq/dt of it (exact on a motion of degree <= 3 in t, such as a free flight;
    O(dt^4) in q, O(dt^3) in v otherwise). Rows at the same time (before and after an impact)
    and rows with impacts between them (a run with t_eval) are joined by a straight line."""
    t, q, v = np.asarray(traj.t, dtype=float), np.asarray(traj.q), np.asarray(traj.v)
    if not traj.step_counts or len(t) < 2 or t[-1] <= t[0]:
        return t, q, v
    dt = np.diff(t)
    pieces = np.ceil(points * dt / (t[-1] - t[0])).astype(np.int64)
    impacts = traj.saved.get("impacts")
    smooth = dt > 0
    if impacts is not None:
        smooth &= np.diff(impacts[:, 0]) == 0
    pieces[~smooth] = 1
    # s in [0, 1) along each row interval, then the last row itself
    start = np.repeat(np.arange(len(dt)), pieces)
    s = np.arange(len(start)) - np.repeat(np.cumsum(pieces) - pieces, pieces)
    s = s / pieces[start]
    h = dt[start][:, None]
    s = s[:, None]
    q0, q1, v0, v1 = q[start], q[start + 1], v[start], v[start + 1]
    # the cubic Hermite basis on [0, 1]: q = h00 q0 + h10 h v0 + h01 q1 + h11 h v1
    h00, h10 = 2 * s**3 - 3 * s**2 + 1, s**3 - 2 * s**2 + s
    h01, h11 = 3 * s**2 - 2 * s**3, s**3 - s**2
    curve_q = h00 * q0 + h10 * h * v0 + h01 * q1 + h11 * h * v1
    # dq/dt of the cubic, written around the chord's slope (h = 0 rows: no division by 0)
    slope = (q1 - q0) / np.where(h > 0, h, 1.0)
    curve_v = (6 * s - 6 * s**2) * slope + (3 * s**2 - 4 * s + 1) * v0 + (3 * s**2 - 2 * s) * v1
    straight = ~smooth[start]
    curve_q[straight], curve_v[straight] = q0[straight], v0[straight]
    return (np.append(t[start] + s[:, 0] * dt[start], t[-1]), np.vstack((curve_q, q[-1:])),
            np.vstack((curve_v, v[-1:])))


def _panels(traj):
    """[(y label, draw(ax))] of the diagnostics ``traj`` has, in display order."""
    panels = [_energy_panel(traj)]
    if traj.constraint_error is not None:
        panels.append(("|Phi|, |J v|", lambda ax: _constraint_errors(ax, traj)))
        # lam_i multiplies constraint i (the names are the expressions: too long for a legend)
        labels = [f"lam_{i}" for i in range(traj.multipliers.shape[1])]
        panels.append(("multipliers", lambda ax: _lines(ax, traj.t, traj.multipliers, labels)))
    state = traj.element_state
    if state.shape[1]:
        names = traj.element_names if len(traj.element_names) == state.shape[1] else [
            f"element_{i}" for i in range(state.shape[1])]
        panels.append(("element state", lambda ax: _lines(ax, traj.t, state, names)))
    return panels


def _steps(traj):
    """How the run chose its steps: "h = 0.001", or for an adaptive run its tolerances (the
    mean step says little about an adaptive run)."""
    if not traj.step_counts:
        return f"h = {traj.h:g}"
    tolerances = [f"{name}={traj.settings[name]:g}" for name in ("rtol", "atol")
                  if isinstance(traj.settings.get(name), (int, float))]
    return ", ".join(["adaptive"] + tolerances)


def _energy_panel(traj):
    """E - E0, or E - E0 - W with the work W (S,) when the trajectory has one."""
    if traj.work is not None:
        label = "E - E0 - W"
        return label, lambda ax: ax.plot(traj.t, traj.energy_balance, lw=1, label=label)
    label = "E - E0"
    return label, lambda ax: ax.plot(traj.t, traj.energy_error, lw=1, label=label)


def _constraint_errors(ax, traj):
    # rattle often holds Phi to exactly 0: zeros are drawn on a floor just below every nonzero
    # value (a gap would hide them, a floor of 1e-300 would squash the axis)
    both = np.concatenate((traj.constraint_error, traj.velocity_constraint_error))
    floor = min(1e-17, both[both > 0].min(initial=1.0) / 10)
    for values, label in ((traj.constraint_error, "|Phi|"),
                          (traj.velocity_constraint_error, "|J v|")):
        ax.semilogy(traj.t, np.maximum(values, floor), lw=1, label=label)
    ax.legend(loc="upper right", fontsize="small")


def _lines(ax, t, values, labels):
    for i, label in enumerate(labels):
        ax.plot(t, values[:, i], lw=1, label=label)
    ax.legend(loc="upper right", fontsize="small", ncol=2)

