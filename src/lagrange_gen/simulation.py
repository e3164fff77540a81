"""Python driver: integrate a generated module with a stepper, get a Trajectory.

    from lagrange_gen.simulation import simulate
    traj = simulate("models/cart_pendulum.py", method="midpoint", q0=[0.1, 0.5], t_end=10, h=1e-3)
    traj.plot("traj.png"); traj.to_npz("traj.npz")

The integration itself runs inside the generated module's jitted ``run_<method>`` (see
steppers/registry.py), in chunks of steps so that a progress bar can be shown; this driver only
checks inputs (run_checks: element coefficients, step count, time resolution, memory), allocates
outputs, turns status codes into exceptions that name the step, the time, the state and (for
Newton) the residual (failures.py), and warns when a conservative run lost its energy
(energy_check.py).
"""

from __future__ import annotations

import math
import sys
import time
import types
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from . import run_checks
from . import status as st
from .energy_check import energy_warning
from .errors import EnergyWarning, SimulationError
from .failures import raise_for_status
from .keys import regeneration_command_for
from .params import resolve_params
from .steppers import registry
from .steppers.base import N_STATS, STAT_ENERGY, STAT_ITERS, STAT_RESIDUAL
from .steppers.spec import make_settings
from .trajectory import Trajectory

__all__ = ["simulate", "Trajectory", "load_module"]

#: Steps per call into the jitted loop (a multiple of save_every is used): large enough that the
#: Python overhead per chunk (a few microseconds) is negligible, small enough for a progress bar.
CHUNK_STEPS = 200_000


def load_module(module_or_path, out_dir="generated", method=None, force=False):
    """A generated module from: the module itself, a generated .py, or a model file (generated
    into ``out_dir`` first when missing or stale, keeping the freeze, build options and methods
    of the module on disk, see loader.load). When the module lacks the glue of the method that
    runs ``method`` on it (e.g. nonsmooth_euler for implicit_euler on a model with elements), it
    is regenerated with that method added. ``force`` overwrites a module generated from another
    model file or with another freeze."""
    if isinstance(module_or_path, types.ModuleType):
        return module_or_path
    from .loader import load
    module = load(Path(module_or_path), out_dir=out_dir, force=force)
    if method is None or getattr(module, "KEY", None) is None:
        return module
    runs = _element_method(module, method)
    if runs in registry.METHODS and not hasattr(module, f"run_{runs}"):
        module = load(Path(module_or_path), out_dir=out_dir, methods=[runs], force=force)
    return module


def _n_steps(t0, t_end, h):
    """Whole steps to reach t_end; rounded up when (t_end - t0) / h is not an integer."""
    ratio = (t_end - t0) / h
    nearest = round(ratio)
    if abs(ratio - nearest) <= 1e-9 * max(1.0, abs(ratio)):
        return int(nearest)
    return int(math.ceil(ratio))


def _runner(module, method):
    if method not in registry.METHODS:
        raise SimulationError(f"unknown method {method!r}; known: {', '.join(registry.METHODS)}")
    run = getattr(module, f"run_{method}", None)
    if run is None:
        have = ", ".join(getattr(module, "METHODS", ())) or "none"
        raise SimulationError(
            f"{module.NAME}: module {module.__file__} was generated without method {method!r} "
            f"(it has: {have}); run `{regeneration_command_for(module, methods=[method])}`")
    return run


def _element_method(module, method):
    """The method that actually runs: implicit_euler becomes nonsmooth_euler on a model with
    nonsmooth elements; a method that cannot treat them is refused, naming them."""
    names = tuple(getattr(module, "ELEMENTS", ()))
    runs = registry.runs_as(method, len(names)) if method in registry.METHODS else method
    if not names or runs in registry.NONSMOOTH_METHODS:
        return runs
    raise SimulationError(
        f"{module.NAME}: method {method!r} cannot treat the nonsmooth element(s) {', '.join(names)} "
        f"(no silent regularization); use method='implicit_euler' (exact Saint-Venant return map, "
        f"Moreau-Jean dry friction)")


def _element_energy(module, p, state):
    """Elastic energy sum_e k_e u_e^2 / 2 stored in the Saint-Venant elements, (S,)."""
    if not module.N_ELEMENTS:
        return 0.0
    coef = run_checks.element_coefficients(module, p)
    k = np.where(coef[:, 2] == 0.0, coef[:, 0], 0.0)
    return 0.5 * (state**2 * k).sum(axis=1)


def simulate(module_or_path, method="midpoint", q0=None, v0=None, *, t_end, h, params=None,
             save_every=1, t0=0.0, progress=False, out_dir="generated", element_state0=None,
             force=False, **settings) -> Trajectory:
    """Integrate a generated model from t0 to t_end with fixed step h.

    module_or_path: a generated module, the path of a generated .py, or a model file (generated
        into out_dir when missing or stale; see load_module, and ``force`` there).
    method: one of steppers.registry.METHODS.
    q0, v0: initial coordinates and velocities (n,), default zeros.
    params: dict {name: value} overriding the defaults, or a full sequence in PARAMS order; a
        parameter without default must be given.
    save_every: keep every save_every-th state (the initial and the final state are always kept).
    element_state0: initial states of the nonsmooth elements (ne,), default 0 (virgin material).
        On models with elements, method implicit_euler runs nonsmooth_euler; the trajectory's
        energy then includes the elastic energy k u^2 / 2 stored in Saint-Venant elements.
    settings: the method's settings by name (its SPEC.settings record; unknown names are
        refused): blowup_bound (BlowUp when |q| or |v| exceeds it) for every method;
        newton_tol (relative to max(1, |unknown|), see steppers.base.newton_converged) and
        max_iter for the implicit ones; newton_always (the Newton path of the partitioned
        methods even when the model allows the explicit one); spook's compliance (epsilon >= 0)
        and relaxation (d > 0); index1's baumgarte = (alpha, beta).
    Constrained models (``constraints=`` in the model) need a constrained method
    (steppers.registry.CONSTRAINED_METHODS); q0, v0 off the constraints are projected onto them
    with a warning (lagrange_gen.consistent), and the Trajectory carries the multipliers and
    max|Phi|, max|J v| per saved state.
    The final time is t0 + n_steps h with n_steps = (t_end - t0) / h rounded up to a whole step.
    Raises SimulationError (bad input, one line naming it), NewtonDivergence (its subclass
    SingularNewtonMatrix: a singular Newton matrix), SingularMass, BlowUp (non-finite or past
    blowup_bound). A conservative run whose energy error passes energy_check.ENERGY_FRACTION of
    its energy scale warns (EnergyWarning, the line also in Trajectory.warnings).
    """
    module = load_module(module_or_path, out_dir, method, force)
    method = _element_method(module, method)
    from .consistent import check_method
    check_method(module, method)
    run = _runner(module, method)
    spec = registry.spec(method)
    n = module.N_COORDS
    run_checks.check_scalars(h, t0, t_end, save_every)
    config = make_settings(spec, settings)
    q = run_checks.vector("q0", q0, n, module.COORDS)
    v = run_checks.vector("v0", v0, n, module.COORDS)
    p = resolve_params(module.PARAMS, module.DEFAULTS, params, model=module.NAME,
                       frozen=getattr(module, "FROZEN", None))
    run_checks.check_element_coefficients(module, p)
    h, t0, save_every = float(h), float(t0), int(save_every)
    run_checks.check_step_count(t0, float(t_end), h)
    n_steps = _n_steps(t0, float(t_end), h)
    run_checks.check_time_resolution(t0, t0 + n_steps * h, h, n_steps)
    n_saved = spec.n_saved(n, module.N_CONSTRAINTS, module.N_ELEMENTS)
    run_checks.check_memory(module.NAME, n_steps, save_every, n, n_saved)
    initial = np.zeros(0)
    if spec.constraints:
        q, v, initial = _constrained_start(module, q, v, p, t0,
                                           getattr(config, "newton_tol", 1e-12))
    elif n_saved:
        initial = run_checks.vector("element_state0", element_state0, n_saved, module.ELEMENTS)
    task = _Task(module, spec, run, p, config, h, t0, n_steps, save_every)
    out = _allocate(run_checks.saved_rows(n_steps, save_every), n, n_saved, initial)
    compile_time, wall = _integrate(task, q, v, out, progress)
    return _trajectory(task, out, wall, compile_time)


@dataclass
class _Task:
    """What one run integrates: the module, the method and its glue, and the run's numbers."""

    module: types.ModuleType
    spec: object        # the method's Spec
    run: object
    p: np.ndarray
    settings: tuple     # the method's settings record
    h: float
    t0: float
    n_steps: int
    save_every: int

    @property
    def method(self):
        return self.spec.name

    @property
    def max_iter(self):
        return getattr(self.settings, "max_iter", 0)


def _allocate(rows, n, n_saved, initial):
    """Output arrays {t (S,), q, v (S, n), stats (S, N_STATS), extra (S, n_saved)}; row 0 of
    extra holds the initial extra data (multipliers and residuals, or element states).
    The n_saved columns of extra are the method's saved fields (SPEC.saved)."""
    out = dict(t=np.empty(rows), q=np.empty((rows, n)), v=np.empty((rows, n)),
               stats=np.zeros((rows, N_STATS)), extra=np.zeros((rows, n_saved)),
               events=np.zeros((0, 3 + 2 * n)))
    if n_saved:
        out["extra"][0] = initial
    return out


def _integrate(task, q, v, out, progress):
    """Run the glue chunk by chunk from (q, v), filling ``out``; fills out["last"] and
    out["rows"] (rows used). Returns (compile seconds, integration seconds). Raises the
    exception of a failure status (failures.raise_for_status)."""
    m, n, h, t0 = task.module, task.module.N_COORDS, task.h, task.t0
    last = np.empty(2 * n + 3 + out["extra"].shape[1])
    compile_time = _warm_up(task.run, q, v, t0, h, task.p, task.settings,
                            out["extra"][:1].copy(), last.copy(), out["events"])
    chunk = max(1, CHUNK_STEPS // task.save_every) * task.save_every
    bar = _ProgressBar(task.n_steps) if progress else None
    start = time.perf_counter()
    done, row = 0, 0
    while True:
        k = min(chunk, task.n_steps - done)
        rows = slice(row, row + k // task.save_every + 1)
        # Row `row` is the previous chunk's last save and this chunk's initial state: keep its
        # Newton statistics, which belong to the steps before it.
        kept = out["stats"][row].copy()
        code, steps, _ = task.run(q, v, t0 + done * h, h, k, task.save_every, task.p,
                                  task.settings, out["t"][rows], out["q"][rows], out["v"][rows],
                                  out["stats"][rows], out["extra"][rows], last, out["events"])
        if row > 0:
            out["stats"][row, STAT_ITERS:] = kept[STAT_ITERS:]
        if code != st.OK:
            raise_for_status(code, m, task.method, done + steps + 1, task.n_steps, last,
                             task.max_iter, h, task.p)
        q, v = last[1:1 + n].copy(), last[1 + n:1 + 2 * n].copy()
        done += k
        row += k // task.save_every
        if bar:
            bar.update(done)
        if done >= task.n_steps:
            break
    wall = time.perf_counter() - start
    if bar:
        bar.close()
    out["last"], out["rows"] = last, row + 1
    return compile_time, wall


def _trajectory(task, out, wall, compile_time):
    """The Trajectory of a finished run: times t0 + k h (not accumulated, independent of the
    chunking), the final state when it is not on a save, energies, and the energy warning."""
    m, n, h, p = task.module, task.module.N_COORDS, task.h, task.p
    last, row, n_saved = out["last"], out["rows"] - 1, out["extra"].shape[1]
    out["t"][:row + 1] = task.t0 + h * task.save_every * np.arange(row + 1)
    if task.n_steps % task.save_every:
        row += 1
        q, v = last[1:1 + n], last[1 + n:1 + 2 * n]
        energy = m.energy(np.ascontiguousarray(q), np.ascontiguousarray(v),
                          task.t0 + task.n_steps * h, p)
        if not math.isfinite(energy):
            raise_for_status(st.NON_FINITE, m, task.method, task.n_steps, task.n_steps, last,
                             task.max_iter, h, p)
        out["t"][row], out["q"][row], out["v"][row] = task.t0 + task.n_steps * h, q, v
        out["stats"][row] = (energy, last[1 + 2 * n], last[2 + 2 * n])
        out["extra"][row] = last[3 + 2 * n:3 + 2 * n + n_saved]
    layout = task.spec.saved_layout(n, m.N_CONSTRAINTS, m.N_ELEMENTS)
    saved = {name: out["extra"][:, start:start + width].copy() for name, start, width in layout}
    energy = out["stats"][:, STAT_ENERGY]
    if "element_state" in saved:
        energy = energy + _element_energy(m, p, saved["element_state"])
    traj = Trajectory(t=out["t"], q=out["q"], v=out["v"], energy=energy,
                      newton_iters=out["stats"][:, STAT_ITERS].copy(),
                      newton_residual=out["stats"][:, STAT_RESIDUAL].copy(), method=task.method,
                      h=h, model=m.NAME, params=dict(zip(m.PARAMS, p.tolist())),
                      coords=tuple(m.COORDS), n_steps=task.n_steps, wall_time=wall,
                      compile_time=compile_time, saved=saved,
                      element_names=tuple(m.ELEMENTS) if task.spec.elements else (),
                      constraint_names=tuple(m.CONSTRAINTS) if task.spec.constraints else ())
    message = energy_warning(m, task.method, traj.q, traj.v, traj.t, traj.energy, p, h)
    if message:
        traj.warnings.append(message)
        # stacklevel 3: _trajectory <- simulate <- the user's call
        warnings.warn(message, EnergyWarning, stacklevel=3)
    return traj


def _constrained_start(module, q, v, p, t0, tol):
    """The consistent initial state and row 0 of the saved fields of a constrained method:
    (q, v, [lam0, max|Phi|, max|J v|])."""
    from .consistent import consistent_initial_state
    # stacklevel 4: the warning points at the user's call of simulate().
    state = consistent_initial_state(module, q, v, p, t0, tol, stacklevel=4)
    initial = np.concatenate((state.lam, [state.phi_norm, state.jv_norm]))
    return np.ascontiguousarray(state.q), np.ascontiguousarray(state.v), initial


def _warm_up(run, q, v, t0, h, p, settings, extra, last, events):
    """Compile (or load from numba's cache) run_<method> with a zero-step call, so that the
    measured wall time is integration only. extra (1, n_saved) and last are scratch copies with
    the method's sizes. Returns the seconds it took."""
    n = q.shape[0]
    start = time.perf_counter()
    run(q, v, t0, h, 0, 1, p, settings, np.empty(1), np.empty((1, n)), np.empty((1, n)),
        np.empty((1, N_STATS)), extra, last, events)
    return time.perf_counter() - start


class _ProgressBar:
    """A one-line text bar on stderr, redrawn only when the percentage changes."""

    def __init__(self, total, width=40, stream=None):
        self.total, self.width, self.stream = max(total, 1), width, stream or sys.stderr
        self.shown = -1
        self.update(0)

    def update(self, done):
        pct = int(100 * done / self.total)
        if pct != self.shown:
            self.shown = pct
            filled = self.width * pct // 100
            self.stream.write(f"\r[{'#' * filled}{' ' * (self.width - filled)}] {pct:3d}%")
            self.stream.flush()

    def close(self):
        self.stream.write("\n")
        self.stream.flush()
