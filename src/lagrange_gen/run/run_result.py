"""The Trajectory of a finished run of simulate: times, states, energies (with the elements'
stored energy), the method's saved fields by its declared layout, located events, the model
file it came from, and the energy warning of a conservative run that lost energy. Arrays as
Trajectory documents them: t (S,), q, v (S, n), energy (S,).
"""

from __future__ import annotations

import functools

import math
import warnings
from pathlib import Path

import numpy as np

from . import checks as run_checks
from .adaptive_driver import C_ACCEPTED, C_EVALS, C_REJECTED
from .energy_check import energy_warning
from ..errors import EnergyWarning
from .failures import raise_for_status
from ..steppers.core import status as st
from ..steppers.core.layout import STAT_ENERGY, STAT_ITERS, STAT_RESIDUAL, STAT_WORK, read_last
from .trajectory import Trajectory

__all__ = ["fixed_step_trajectory", "adaptive_trajectory", "element_energy", "warn_energy_lost"]


def element_energy(module, p, state):
    """Elastic energy sum_e k_e u_e^2 / 2 stored in the Saint-Venant elements, (S,)."""
    coef = run_checks.element_coefficients(module, p)
    k = np.where(coef[:, 2] == 0.0, coef[:, 0], 0.0)
    return 0.5 * (state**2 * k).sum(axis=1)


def fixed_step_trajectory(task, out, wall, compile_time):
    """The Trajectory of a finished fixed-step run: times t0 + k h (not accumulated,
    independent of the chunking), the final state when it is not on a save (or a terminal
    event stopped the run), energies, and the energy warning."""
    m, n, h, p = task.module, task.module.N_COORDS, task.h, task.p
    last, row = out["last"], out["rows"] - 1
    times = out["t"][:row + 1]          # t0 + k (h save_every), written in place
    np.multiply(np.arange(row + 1), h * task.save_every, out=times)
    times += task.t0
    steps = out["steps"]
    if steps % task.save_every or steps < task.n_steps:
        row += 1
        final = read_last(last, n, with_work=True)
        q, v = final.q, final.v
        energy = m.energy(np.ascontiguousarray(q), np.ascontiguousarray(v), float(final.t), p)
        if not math.isfinite(energy):
            raise_for_status(st.NON_FINITE, m, task.method, steps, task.n_steps, last,
                             task.max_iter, h, p)
        out["t"][row], out["q"][row], out["v"][row] = final.t, q, v
        out["stats"][row] = (energy, final.iters, final.resid, final.work)
        out["extra"][row] = final.extra
    rows = slice(0, row + 1)
    traj = _build(task, {k: out[k][rows] for k in ("t", "q", "v", "stats", "extra")},
                  out, steps, h, wall, compile_time)
    return warn_energy_lost(task, traj, h, "reduce h")


def adaptive_trajectory(task, out, t_eval, wall, compile_time):
    """The Trajectory of an adaptive run; with t_eval, only the requested times (row 0, the
    initial state, only when t_eval starts at t0). h = the mean accepted step."""
    rows = {k: out[k] for k in ("t", "q", "v", "stats", "extra")}
    if t_eval is not None and not (len(t_eval) and t_eval[0] == task.t0):
        rows = {k: a[1:] for k, a in rows.items()}
    counters = out["counters"]
    accepted = int(counters[C_ACCEPTED])
    h = (out["last"][0] - task.t0) / max(accepted, 1)
    traj = _build(task, rows, out, accepted, h, wall, compile_time)
    traj.newton_iters[:] = 0.0          # the stats columns hold step counts and error norms
    traj.newton_residual[:] = 0.0
    traj.saved["accepted_steps"] = rows["stats"][:, STAT_ITERS:STAT_ITERS + 1].copy()
    traj.saved["error_norm"] = rows["stats"][:, STAT_RESIDUAL:STAT_RESIDUAL + 1].copy()
    traj.step_counts = dict(accepted=accepted, rejected=int(counters[C_REJECTED]),
                            evaluations=int(counters[C_EVALS]))
    return warn_energy_lost(task, traj, h, "tighten rtol and atol")


def _has_work(module):
    """Whether the run integrated W (steppers/core/work.py): every method, fixed-step and
    adaptive, does on a model whose energy E = T2 - T0 + V is not conserved (WORK; modules
    generated before it have none)."""
    return bool(getattr(module, "WORK", False))


def _build(task, rows, out, steps, h, wall, compile_time):
    """A Trajectory from the saved rows {t, q, v, stats, extra} of a run."""
    m, p, spec = task.module, task.p, task.spec
    extra = rows["extra"]
    saved = {name: extra[:, start:start + width].copy() for name, start, width in task.layout}
    # One copy of the statistics, transposed: each column (energy, Newton iterations and
    # residuals, W) is then a contiguous row of it, without a copy per column.
    stats = rows["stats"].T.copy()
    energy = stats[STAT_ENERGY]
    if "element_state" in saved:
        energy = energy + element_energy(m, p, saved["element_state"])
    return Trajectory(t=rows["t"], q=rows["q"], v=rows["v"], energy=energy,
                      newton_iters=stats[STAT_ITERS], newton_residual=stats[STAT_RESIDUAL],
                      method=spec.name, h=h, model=m.NAME,
                      params=dict(zip(m.PARAMS, p.tolist())), coords=tuple(m.COORDS),
                      n_steps=steps, wall_time=wall, compile_time=compile_time, jit=task.ran,
                      saved=saved, work=stats[STAT_WORK] if _has_work(m) else None,
                      settings=_settings(task.settings),
                      element_names=tuple(m.ELEMENTS) if spec.elements else (),
                      constraint_names=(tuple(m.CONSTRAINTS)
                                        if spec.saves_constraints(m.N_CONSTRAINTS) else ()),
                      events=_events(m, out), source=_source(m))


def _settings(record):
    """{name: value} of a method's settings record (a namedtuple), {} for anything else."""
    as_dict = getattr(record, "_asdict", None)
    return dict(as_dict()) if as_dict is not None else {}


def _source(module):
    """{model_file (absolute), build options, frozen parameters} of a generated module; {} for a
    module without MODEL_PATH (hand-made modules in tests)."""
    if getattr(module, "MODEL_PATH", None) is None:
        return {}
    return dict(model_file=_model_file(module.__file__, module.MODEL_PATH),
                build=dict(module.OPTIONS.get("build", {})),
                frozen=dict(getattr(module, "FROZEN", {})))


@functools.lru_cache(maxsize=256)
def _model_file(module_file, model_path):
    """The absolute model file of a generated module (resolving a path reads the file system,
    a noticeable part of a short run's call)."""
    return str((Path(module_file).parent / model_path).resolve())


def _events(module, out):
    """The located events of a run (steppers/core/events.py), () for a model without events."""
    if not out["n_events"]:
        return ()
    from ..steppers.core.events import events_table
    return events_table(module, out["events"], out["n_events"])


def warn_energy_lost(task, traj, h, advice):
    """``traj`` with the energy warning of a conservative run that lost energy (advice: what to
    change), in traj.warnings and as an EnergyWarning at the user's call of simulate."""
    if task.controlled:         # driven by its inputs: the premise of a conservative model fails
        return traj
    message = energy_warning(task.module, task.method, traj.q, traj.v, traj.t, traj.energy,
                             task.p, h, advice)
    if message:
        traj.warnings.append(message)
        # stacklevel 4: warn_energy_lost <- fixed_step_trajectory or adaptive_trajectory <-
        # simulate <- the user's call
        warnings.warn(message, EnergyWarning, stacklevel=4)
    return traj
