"""The figure of a Trajectory: what a run did, one quantity per axis.

Left column the coordinates, right column their velocities, one row per coordinate (an angle that
winds up to 35 rad no longer flattens the others); below, panels for what the run has: the energy
error E - E0 (or the energy balance E - E0 - W when the trajectory carries the work W of the
non-conservative forces), |Phi| and |J v| and the multipliers of a constrained run, the element
states of a nonsmooth run. Built on matplotlib.figure.Figure (no pyplot, no backend switch), so it
also works inside a notebook, where the returned Figure displays itself.
"""

from __future__ import annotations

import numpy as np

# above this many coordinates, all coordinates share one axis (and all velocities another)
MAX_ROWS = 8
_ROW_HEIGHT = 1.6


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
    for r in range(state_rows):
        which = [r] if n <= MAX_ROWS else list(range(n))
        for col, (values, suffix) in enumerate(((traj.q, ""), (traj.v, "_dot"))):
            ax = fig.add_subplot(grid[r, col], sharex=first)
            first = first or ax
            for i in which:
                ax.plot(traj.t, values[:, i], lw=1, label=traj.coords[i] + suffix)
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
    if path is None:
        return fig
    from pathlib import Path
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    return None


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

