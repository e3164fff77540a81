"""Python driver: integrate a generated module with a stepper, get a Trajectory.

    from lagrange_gen.simulation import simulate
    traj = simulate("models/cart_pendulum.py", method="midpoint", q0=[0.1, 0.5], t_end=10, h=1e-3)
    traj.plot("traj.png"); traj.to_npz("traj.npz")

The integration itself runs inside the generated module's jitted ``run_<method>`` (see
steppers/registry.py), in chunks of steps so that a progress bar can be shown; this driver only
checks inputs, allocates outputs and turns status codes into exceptions that name the step, the
time, the state and (for Newton) the residual.
"""

from __future__ import annotations

import math
import sys
import time
import types
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from . import status as st
from .errors import BlowUp, NewtonDivergence, SimulationError, SingularMass
from .params import resolve_params
from .steppers import registry
from .steppers.base import N_STATS, STAT_ENERGY, STAT_ITERS, STAT_RESIDUAL, make_settings

__all__ = ["simulate", "Trajectory", "load_module"]

#: Steps per call into the jitted loop (a multiple of save_every is used): large enough that the
#: Python overhead per chunk (a few microseconds) is negligible, small enough for a progress bar.
CHUNK_STEPS = 200_000


@dataclass
class Trajectory:
    """Saved states of one simulation.

    t (S,), q (S, n), v (S, n), energy (S,) E = T + V, newton_iters (S,) Newton iterations summed
    over the steps since the previous saved row, newton_residual (S,) the largest final Newton
    residual over those steps. S = n_steps // save_every + 1 (+1 when the final state does not
    fall on a save).
    """

    t: np.ndarray
    q: np.ndarray
    v: np.ndarray
    energy: np.ndarray
    newton_iters: np.ndarray
    newton_residual: np.ndarray
    method: str
    h: float
    model: str
    params: dict
    coords: tuple
    n_steps: int
    wall_time: float = 0.0       # integration only, seconds
    compile_time: float = 0.0    # compiling or loading run_<method> from numba's cache, seconds
    extra: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    element_names: tuple = ()
    constraint_names: tuple = ()

    @property
    def multipliers(self) -> np.ndarray:
        """(S, m): the constraint forces lam (H qdd = rhs + J^T lam) at each saved state, from a
        constrained method (see its module docstring for which of its multipliers it reports)."""
        return self.extra[:, :len(self.constraint_names)]

    @property
    def constraint_error(self) -> np.ndarray:
        """(S,): max_i |Phi_i(q)| at each saved state (constrained methods)."""
        return self.extra[:, len(self.constraint_names)]

    @property
    def velocity_constraint_error(self) -> np.ndarray:
        """(S,): max_i |(J(q) v)_i| at each saved state (constrained methods)."""
        return self.extra[:, len(self.constraint_names) + 1]

    @property
    def element_state(self) -> np.ndarray:
        """(S, ne): per nonsmooth element, u (elastic strain of a Saint-Venant element) or r (the
        dry-friction force) at each saved state."""
        return self.extra[:, :len(self.element_names)]

    @property
    def energy_error(self) -> np.ndarray:
        """E - E0 (S,)."""
        return self.energy - self.energy[0]

    @property
    def max_energy_error(self) -> float:
        return float(np.max(np.abs(self.energy_error)))

    def to_npz(self, path):
        """Write every array and the metadata to a .npz file."""
        _parent(path)
        np.savez(path, t=self.t, q=self.q, v=self.v, energy=self.energy,
                 newton_iters=self.newton_iters, newton_residual=self.newton_residual,
                 method=self.method, h=self.h, model=self.model, coords=np.array(self.coords),
                 param_names=np.array(list(self.params)),
                 param_values=np.array(list(self.params.values()), dtype=float),
                 n_steps=self.n_steps, element_names=np.array(self.element_names, dtype=str),
                 element_state=self.element_state,
                 constraint_names=np.array(self.constraint_names, dtype=str),
                 multipliers=self.multipliers, **self._constraint_arrays())

    def _constraint_arrays(self):
        if not self.constraint_names:
            return {}
        return dict(constraint_error=self.constraint_error,
                    velocity_constraint_error=self.velocity_constraint_error)

    def to_csv(self, path):
        """Write one row per saved state: t, coordinates, velocities, energy, newton_iters (and
        for a constrained method lam_0..lam_m-1, max|Phi|, max|J v|)."""
        header = ["t", *self.coords, *(f"{c}_dot" for c in self.coords), "energy", "newton_iters"]
        data = np.column_stack([self.t, self.q, self.v, self.energy, self.newton_iters])
        if self.constraint_names:
            header += [f"lam_{i}" for i in range(len(self.constraint_names))]
            header += ["constraint_error", "velocity_constraint_error"]
            data = np.column_stack([data, self.extra])
        _parent(path)
        np.savetxt(path, data, delimiter=",", header=",".join(header), comments="", fmt="%.17g")

    def plot(self, path):
        """PNG (matplotlib Agg): coordinates vs t, and the energy error E - E0 vs t."""
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, (ax_q, ax_e) = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
        for i, name in enumerate(self.coords):
            ax_q.plot(self.t, self.q[:, i], label=name)
        ax_q.set_ylabel("q")
        ax_q.legend(loc="upper right")
        ax_q.set_title(f"{self.model}: {self.method}, h = {self.h:g}")
        ax_e.plot(self.t, self.energy_error)
        ax_e.set_ylabel("E - E0")
        ax_e.set_xlabel("t")
        fig.tight_layout()
        _parent(path)
        fig.savefig(path, dpi=110)
        plt.close(fig)

    def __repr__(self):
        return (f"Trajectory({self.model}, {self.method}, h={self.h:g}, steps={self.n_steps}, "
                f"saved={len(self.t)}, t=[{self.t[0]:g}, {self.t[-1]:g}])")


def _parent(path):
    Path(path).parent.mkdir(parents=True, exist_ok=True)


def load_module(module_or_path, out_dir="generated"):
    """A generated module from: the module itself, a generated .py, or a model file (generated
    into ``out_dir`` first when missing or stale)."""
    if isinstance(module_or_path, types.ModuleType):
        return module_or_path
    from .loader import load
    return load(Path(module_or_path), out_dir=out_dir)


def _vector(name, value, n, coords):
    if value is None:
        return np.zeros(n)
    try:
        arr = np.asarray(value, dtype=np.float64).reshape(-1)
    except (TypeError, ValueError):
        raise SimulationError(f"{name} must be a sequence of {n} numbers, got {value!r}") from None
    if arr.shape[0] != n:
        raise SimulationError(f"{name} has {arr.shape[0]} entries but the model has {n} "
                              f"coordinates ({', '.join(coords)})")
    if not np.all(np.isfinite(arr)):
        raise SimulationError(f"{name} contains a non-finite value: {arr.tolist()}")
    return np.ascontiguousarray(arr)


def _n_steps(t0, t_end, h):
    """Whole steps to reach t_end; rounded up when (t_end - t0) / h is not an integer."""
    ratio = (t_end - t0) / h
    nearest = round(ratio)
    if abs(ratio - nearest) <= 1e-9 * max(1.0, abs(ratio)):
        return int(nearest)
    return int(math.ceil(ratio))


def _check_scalars(h, t0, t_end, save_every, newton_tol, max_iter):
    for name, value in (("h", h), ("t0", t0), ("t_end", t_end), ("newton_tol", newton_tol)):
        if not isinstance(value, (int, float, np.floating, np.integer)) or not math.isfinite(value):
            raise SimulationError(f"{name} must be a finite number, got {value!r}")
    if h <= 0:
        raise SimulationError(f"step size h must be > 0, got {h}")
    if t_end < t0:
        raise SimulationError(f"t_end = {t_end} is before t0 = {t0}")
    if int(save_every) != save_every or save_every < 1:
        raise SimulationError(f"save_every must be a positive integer, got {save_every!r}")
    if newton_tol <= 0:
        raise SimulationError(f"newton_tol must be > 0, got {newton_tol}")
    if int(max_iter) != max_iter or max_iter < 1:
        raise SimulationError(f"max_iter must be a positive integer, got {max_iter!r}")


def _runner(module, method):
    if method not in registry.METHODS:
        raise SimulationError(f"unknown method {method!r}; known: {', '.join(registry.METHODS)}")
    run = getattr(module, f"run_{method}", None)
    if run is None:
        have = ", ".join(getattr(module, "METHODS", ())) or "none"
        model = getattr(module, "MODEL_PATH", None)
        where = Path(module.__file__).parent / model if model else Path("<model file>")
        raise SimulationError(
            f"{module.NAME}: module {module.__file__} was generated without method {method!r} "
            f"(it has: {have}); run `lagrange-gen --methods "
            f"{','.join(sorted(set(getattr(module, 'METHODS', ())) | {method}))} {where}`")
    return run


def _format_state(coords, q, v):
    parts = [f"{c}={x:.6g}" for c, x in zip(coords, q)]
    parts += [f"{c}_dot={x:.6g}" for c, x in zip(coords, v)]
    return ", ".join(parts)


def _raise_for_status(code, module, method, step, n_steps, last, max_iter, h, p):
    """Turn a stepper status into the matching exception (step is 1-based)."""
    n = module.N_COORDS
    t, q, v, resid = last[0], last[1:1 + n], last[1 + n:1 + 2 * n], last[2 + 2 * n]
    state = _format_state(module.COORDS, q, v)
    where = f"{module.NAME}, {method}: step {step} of {n_steps} (t = {t:.9g}, h = {h:g})"
    kwargs = dict(step=step, time=float(t), state=np.concatenate([q, v]), residual=float(resid))
    if code == st.NEWTON_DIVERGED:
        raise NewtonDivergence(f"{where}: Newton did not converge in {max_iter} iterations "
                               f"(residual {resid:.3g}) from {state}; reduce h or raise max_iter",
                               **kwargs)
    if code == st.SINGULAR_MASS:
        hint = ""
        if method in registry.CONSTRAINED_METHODS:
            from .consistent import diagnose_singular
            hint = diagnose_singular(module, np.ascontiguousarray(q), p)
        raise SingularMass(f"{where}: singular mass matrix (or Newton matrix) at {state}{hint}",
                           **kwargs)
    if code == st.NON_FINITE:
        raise BlowUp(f"{where}: the state became non-finite: {state}", **kwargs)
    if code == st.UNSTABLE:
        raise BlowUp(f"{where}: the state grew past the blow-up bound (unstable at this h?): "
                     f"{state}", **kwargs)
    raise SimulationError(f"{where}: stepper returned unknown status {code}", **kwargs)


def _element_method(module, method):
    """The method that actually runs: implicit_euler becomes nonsmooth_euler on a model with
    nonsmooth elements; a method that cannot treat them is refused, naming them."""
    names = tuple(getattr(module, "ELEMENTS", ()))
    if not names or method in registry.NONSMOOTH_METHODS:
        return method
    if method == "implicit_euler":
        return "nonsmooth_euler"
    raise SimulationError(
        f"{module.NAME}: method {method!r} cannot treat the nonsmooth element(s) {', '.join(names)} "
        f"(no silent regularization); use method='implicit_euler' (exact Saint-Venant return map, "
        f"Moreau-Jean dry friction)")


def _extra_layout(module, method):
    """(saved, total) columns of out_extra for a method on a module."""
    if method == "nonsmooth_euler":
        from .steppers.nonsmooth_euler import extra_size
        return extra_size(module.N_COORDS, module.N_ELEMENTS)
    if method in registry.CONSTRAINED_METHODS:
        from .steppers.constrained import extra_size
        return extra_size(module.N_COORDS, module.N_CONSTRAINTS)
    return 0, 0


def _element_energy(module, p, state):
    """Elastic energy sum_e k_e u_e^2 / 2 stored in the Saint-Venant elements, (S,)."""
    ne, n = module.N_ELEMENTS, module.N_COORDS
    if not ne:
        return 0.0
    s, G, coef = np.empty(ne), np.empty((ne, n)), np.empty((ne, 3))
    module.elements(np.zeros(n), p, s, G, coef)    # coefficients depend on parameters only
    k = np.where(coef[:, 2] == 0.0, coef[:, 0], 0.0)
    return 0.5 * (state**2 * k).sum(axis=1)


def simulate(module_or_path, method="midpoint", q0=None, v0=None, *, t_end, h, params=None,
             save_every=1, newton_tol=1e-12, max_iter=50, t0=0.0, progress=False,
             blowup_bound=1e150, newton_always=False, out_dir="generated",
             element_state0=None, compliance=0.0, relaxation=2.0,
             baumgarte=(0.0, 0.0)) -> Trajectory:
    """Integrate a generated model from t0 to t_end with fixed step h.

    module_or_path: a generated module, the path of a generated .py, or a model file (generated
        into out_dir when missing or stale).
    method: one of steppers.registry.METHODS.
    q0, v0: initial coordinates and velocities (n,), default zeros.
    params: dict {name: value} overriding the defaults, or a full sequence in PARAMS order; a
        parameter without default must be given.
    save_every: keep every save_every-th state (the initial and the final state are always kept).
    newton_tol, max_iter: Newton tolerance, relative to max(1, |unknown|) (see
        steppers.base.newton_converged), and the iteration cap per solve.
    blowup_bound: BlowUp when |q| or |v| exceeds it.
    newton_always: use the Newton path of symplectic_euler / verlet / composition even when the
        model allows the explicit one (constant H, velocity-free forces).
    element_state0: initial states of the nonsmooth elements (ne,), default 0 (virgin material).
        On models with elements, method implicit_euler runs nonsmooth_euler; the trajectory's
        energy then includes the elastic energy k u^2 / 2 stored in Saint-Venant elements.
    Constrained models (``constraints=`` in the model) need a constrained method
    (steppers.registry.CONSTRAINED_METHODS); q0, v0 off the constraints are projected onto them
    with a warning (lagrange_gen.consistent), and the Trajectory carries the multipliers and
    max|Phi|, max|J v| per saved state. compliance (epsilon >= 0) and relaxation (d > 0) are
    spook's; baumgarte = (alpha, beta) is index1's optional stabilization.
    The final time is t0 + n_steps h with n_steps = (t_end - t0) / h rounded up to a whole step.
    Raises SimulationError (bad input), NewtonDivergence, SingularMass, BlowUp.
    """
    module = load_module(module_or_path, out_dir)
    method = _element_method(module, method)
    constrained = method in registry.CONSTRAINED_METHODS
    from .consistent import check_method
    check_method(module, method, registry.CONSTRAINED_METHODS)
    run = _runner(module, method)
    n = module.N_COORDS
    _check_scalars(h, t0, t_end, save_every, newton_tol, max_iter)
    q = _vector("q0", q0, n, module.COORDS)
    v = _vector("v0", v0, n, module.COORDS)
    p = resolve_params(module.PARAMS, module.DEFAULTS, params, model=module.NAME,
                       frozen=getattr(module, "FROZEN", None))
    h, t0, save_every, max_iter = float(h), float(t0), int(save_every), int(max_iter)
    settings = make_settings(newton_tol, max_iter, blowup_bound, 1 if newton_always else 0)
    if constrained:
        settings, q, v, initial = _constrained_setup(module, q, v, p, t0, settings, compliance,
                                                     relaxation, baumgarte)
    n_steps = _n_steps(t0, float(t_end), h)
    rows = n_steps // save_every + 1 + (1 if n_steps % save_every else 0)
    out_t, out_q, out_v = np.empty(rows), np.empty((rows, n)), np.empty((rows, n))
    n_saved, n_extra = _extra_layout(module, method)
    # Only the n_saved leading entries of the method's extra buffer are kept per row; the rest
    # is scratch that run_loop sizes from `last` (steppers/base.py).
    out_stats, out_extra = np.zeros((rows, N_STATS)), np.zeros((rows, n_saved))
    if constrained:
        out_extra[0] = initial
    elif n_saved:
        out_extra[0, :n_saved] = _vector("element_state0", element_state0, n_saved, module.ELEMENTS)
    last = np.empty(2 * n + 3 + n_extra)
    chunk = max(1, CHUNK_STEPS // save_every) * save_every
    compile_time = _warm_up(run, q, v, t0, h, p, settings, out_extra[:1].copy(), last.copy())
    bar = _ProgressBar(n_steps) if progress else None
    start = time.perf_counter()
    done, row = 0, 0
    while True:
        k = min(chunk, n_steps - done)
        saves = k // save_every
        # Row `row` is the previous chunk's last save and this chunk's initial state: keep its
        # Newton statistics, which belong to the steps before it.
        kept = out_stats[row].copy()
        code, steps = run(q, v, t0 + done * h, h, k, save_every, p, settings,
                          out_t[row:row + saves + 1], out_q[row:row + saves + 1],
                          out_v[row:row + saves + 1], out_stats[row:row + saves + 1],
                          out_extra[row:row + saves + 1], last)
        if row > 0:
            out_stats[row, STAT_ITERS:] = kept[STAT_ITERS:]
        if code != st.OK:
            _raise_for_status(code, module, method, done + steps + 1, n_steps, last, max_iter, h,
                              p)
        q, v = last[1:1 + n].copy(), last[1 + n:1 + 2 * n].copy()
        done += k
        row += saves
        if bar:
            bar.update(done)
        if done >= n_steps:
            break
    # Times as t0 + k h, independent of how the run was chunked (each chunk adds its own i h).
    out_t[:row + 1] = t0 + h * save_every * np.arange(row + 1)
    if n_steps % save_every:
        row += 1
        out_t[row], out_q[row], out_v[row] = t0 + n_steps * h, q, v
        out_stats[row] = (module.energy(q, v, out_t[row], p), last[1 + 2 * n], last[2 + 2 * n])
        out_extra[row] = last[3 + 2 * n:3 + 2 * n + n_saved]
    wall = time.perf_counter() - start
    if bar:
        bar.close()
    elements = out_extra[:, :n_saved].copy()
    energy = out_stats[:, STAT_ENERGY] + _element_energy(module, p, elements)
    return Trajectory(t=out_t, q=out_q, v=out_v, energy=energy,
                      newton_iters=out_stats[:, STAT_ITERS].copy(),
                      newton_residual=out_stats[:, STAT_RESIDUAL].copy(), method=method, h=h,
                      model=module.NAME, params=dict(zip(module.PARAMS, p.tolist())),
                      coords=tuple(module.COORDS), n_steps=n_steps, wall_time=wall,
                      compile_time=compile_time, extra=elements,
                      element_names=tuple(getattr(module, "ELEMENTS", ())) if n_saved and not
                      constrained else (),
                      constraint_names=tuple(module.CONSTRAINTS) if constrained else ())


def _constrained_setup(module, q, v, p, t0, settings, compliance, relaxation, baumgarte):
    """Settings of the constrained methods, the consistent initial state, and row 0 of
    out_extra: (settings, q, v, [lam0, max|Phi|, max|J v|])."""
    from .consistent import consistent_initial_state
    from .steppers.constrained import make_constrained_settings
    for name, value, positive in (("compliance", compliance, False), ("relaxation", relaxation, True)):
        number = isinstance(value, (int, float, np.floating, np.integer)) and math.isfinite(value)
        if not number or value < 0 or (positive and value == 0):
            raise SimulationError(f"{name} must be a finite number {'> 0' if positive else '>= 0'}, "
                                  f"got {value!r}")
    try:
        alpha, beta = (float(x) for x in baumgarte)
    except (TypeError, ValueError):
        raise SimulationError(f"baumgarte must be (alpha, beta), got {baumgarte!r}") from None
    if not (alpha >= 0 and beta >= 0 and math.isfinite(alpha + beta)):
        raise SimulationError(f"baumgarte coefficients must be finite and >= 0, got {baumgarte!r}")
    tol, max_iter, bound, mode = settings[:4]
    settings = make_constrained_settings(tol, max_iter, bound, mode, float(compliance),
                                         float(relaxation), alpha, beta)
    # stacklevel 4: the warning points at the user's call of simulate().
    state = consistent_initial_state(module, q, v, p, t0, tol, stacklevel=4)
    initial = np.concatenate((state.lam, [state.phi_norm, state.jv_norm]))
    return settings, np.ascontiguousarray(state.q), np.ascontiguousarray(state.v), initial


def _warm_up(run, q, v, t0, h, p, settings, extra, last):
    """Compile (or load from numba's cache) run_<method> with a zero-step call, so that the
    measured wall time is integration only. extra (1, n_saved) and last are scratch copies with
    the method's sizes. Returns the seconds it took."""
    n = q.shape[0]
    start = time.perf_counter()
    run(q, v, t0, h, 0, 1, p, settings, np.empty(1), np.empty((1, n)), np.empty((1, n)),
        np.empty((1, N_STATS)), extra, last)
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
