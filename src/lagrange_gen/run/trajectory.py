"""The result of lagrange_gen.simulate: saved states, energies, Newton statistics, writers.

    traj = simulate(...); traj.to_npz("traj.npz"); traj.to_csv("traj.csv"); traj.plot("traj.png")
    traj.to_dataframe(); Trajectory.load("traj.npz"); traj.animate("traj.gif")
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .trajectory_io import dataframe, read_npz, write_csv, write_npz


@dataclass
class Trajectory:
    """Saved states of one simulation.

    t (S,), q (S, n), v (S, n), energy (S,) the energy function E = T2 - T0 + V (T + V for a
    scleronomic T), work (S,) or None: W, the work of the non-conservative forces, dissipation
    and explicit time since t0 (steppers/core/work.py; the runs of every method on models whose
    E is not conserved), newton_iters (S,) Newton iterations summed
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
    # the loop that ran (simulate(jit=), lagrange_gen.jit.portable): "specialized",
    # "portable", "portable, then specialized from step k", or on a method's first use
    # "interpreted" (its Python, jit/interpreted.py), "interpreted, then portable from step k"
    jit: str = ""
    saved: dict = field(default_factory=dict)   # {field name: (S, width)}: the method's SPEC.saved
    element_names: tuple = ()
    constraint_names: tuple = ()
    warnings: list = field(default_factory=list)   # one line each (also issued as Python warnings)
    events: tuple = ()          # located events (steppers/core/events.py events_table), in time order
    step_counts: dict = field(default_factory=dict)  # adaptive runs: accepted, rejected, evaluations
    # where the module came from: {"model_file": absolute path, "build": {...}, "frozen": {...}}
    # (what animate needs to rebuild the model's Drawing)
    source: dict = field(default_factory=dict)
    work: np.ndarray | None = None   # W (S,), see above; None when E is conserved
    # the method's settings as the run used them (rtol, atol, newton_tol, ...)
    settings: dict = field(default_factory=dict)
    # simulate(sensitivities=[...]): {name: (S, 2n) for a parameter, (S, 2n, n) for q0/v0}
    sensitivities: dict = field(default_factory=dict)

    def sensitivity(self, name) -> np.ndarray:
        """d(q, v)/d ``name`` at each saved row: (S, 2n) for a parameter, (S, 2n, n) for "q0"
        or "v0" (columns: the initial coordinates or velocities), from a run with
        simulate(..., sensitivities=[name, ...]) (run/sensitivities.py)."""
        if name not in self.sensitivities:
            have = ", ".join(self.sensitivities) or "none"
            raise KeyError(f"Trajectory.sensitivity: {name!r} was not asked for in simulate("
                           f"sensitivities=[...]) (this run has: {have})")
        return self.sensitivities[name]

    @property
    def multipliers(self) -> np.ndarray:
        """(S, m): the constraint forces lam (H qdd = rhs + J^T lam) at each saved state, from a
        constrained method (see its module docstring for which of its multipliers it reports);
        (S, 0) for a run without constraints."""
        lam = self.saved.get("multipliers")
        return lam if lam is not None else np.zeros((len(self.t), 0))

    @property
    def constraint_error(self):
        """(S,): max_i |Phi_i(q)| at each saved state; None for a run without constraints."""
        phi = self.saved.get("constraint_error")
        return None if phi is None or not phi.shape[1] else phi[:, 0]

    @property
    def velocity_constraint_error(self):
        """(S,): max_i |(J(q) v)_i| at each saved state; None for a run without constraints."""
        jv = self.saved.get("velocity_constraint_error")
        return None if jv is None or not jv.shape[1] else jv[:, 0]

    @property
    def element_state(self) -> np.ndarray:
        """(S, ne): per nonsmooth element, u (elastic strain of a Saint-Venant element) or r (the
        dry-friction force) at each saved state; (S, 0) for a run without elements."""
        state = self.saved.get("element_state")
        return state if state is not None else np.zeros((len(self.t), 0))

    @property
    def energy_error(self) -> np.ndarray:
        """E - E0 (S,)."""
        return self.energy - self.energy[0]

    @property
    def max_energy_error(self) -> float:
        return float(np.max(np.abs(self.energy_error)))

    @property
    def energy_balance(self) -> np.ndarray:
        """E - E0 - (W - W0) (S,): zero up to the method's error; E - E0 when the model conserves
        E (``work`` None). (W0 = 0 unless the trajectory was cut from a longer one.) The work of
        contact impulses and forces is not in W: see ``saved["contact_work"]``."""
        if self.work is None:
            return self.energy_error
        return self.energy_error - (np.asarray(self.work) - self.work[0])

    @property
    def max_energy_balance_error(self) -> float:
        return float(np.max(np.abs(self.energy_balance)))

    @property
    def impacts(self) -> np.ndarray:
        """The impacts of an event-driven contact run (dop853_impacts, which saves the
        cumulative ``impacts`` and impulse sums and writes a row after each impact): one row per
        impact and contact that took an impulse, fields t, contact (index in the model's
        CONTACTS), normal, tangent, tangent2 (the impulses; tangent2 along a 3D contact's second
        tangent, else 0). With t_eval the rows after impacts are not
        written: then a row stands for the impacts since the previous one. Empty for other runs."""
        dtype = [("t", np.float64), ("contact", np.int64), ("normal", np.float64),
                 ("tangent", np.float64), ("tangent2", np.float64)]
        count = self.saved.get("impacts")
        if count is None:
            return np.zeros(0, dtype=dtype)
        normal = np.diff(self.saved["normal_impulse_sum"], axis=0)
        tangent = np.diff(self.saved["tangent_impulse_sum"], axis=0)
        second = self.saved.get("tangent2_impulse_sum")
        tangent2 = np.zeros_like(tangent) if second is None else np.diff(second, axis=0)
        rows = []
        for k in np.flatnonzero(np.diff(count[:, 0]) > 0):
            for c in np.flatnonzero((normal[k] != 0) | (tangent[k] != 0) | (tangent2[k] != 0)):
                rows.append((self.t[k + 1], c, normal[k, c], tangent[k, c], tangent2[k, c]))
        return np.array(rows, dtype=dtype)

    def to_npz(self, path):
        """Write every field to a .npz file (run/trajectory_io.py); Trajectory.load reads it back."""
        write_npz(self, path)

    save = to_npz

    @classmethod
    def load(cls, path) -> "Trajectory":
        """The Trajectory saved by to_npz/save (also a .npz of an older writer, without events,
        warnings and source)."""
        return read_npz(cls, path)

    def to_csv(self, path):
        """Write one row per saved state: t, coordinates, velocities, energy, newton_iters and
        the method's saved fields (a field of width w > 1 as name_0..name_w-1; for a constrained
        method lam_0..lam_m-1, constraint_error, velocity_constraint_error)."""
        write_csv(self, path)

    def to_dataframe(self):
        """pandas.DataFrame indexed by t with the columns of to_csv (pandas is the optional extra
        ``lagrange-gen[dataframe]``)."""
        return dataframe(self)

    def plot(self, path=None):
        """Coordinates and velocities (one axis each), energy (balance), and the constraint
        errors and multipliers or element states when the run has them (viz/plot.py). An
        adaptive run's coordinates and velocities are drawn along each step (the cubic Hermite
        curve through its end states, viz.plot.state_curve), not as chords between its rows.
        Writes ``path`` (format from the suffix: .png, .pdf, .svg) or returns the Figure."""
        from ..viz.plot import plot_trajectory
        return plot_trajectory(self, path)

    def animate(self, path, model=None, frames=None, fps=25, dpi=80):
        """Write an animation of the model's Drawing (Model(draw=...)) along this trajectory:
        .gif (Pillow) or .mp4 (ffmpeg). ``model``: a Model or model file; default the model file
        the run came from (self.source). ``frames`` evenly spaced in time (default: real time at
        ``fps``, at most 300). See viz/animate.py."""
        from ..viz.animate import animate
        return animate(self, path, model=model, frames=frames, fps=fps, dpi=dpi)

    def __repr__(self):
        return (f"Trajectory({self.model}, {self.method}, h={self.h:g}, steps={self.n_steps}, "
                f"saved={len(self.t)}, t=[{self.t[0]:g}, {self.t[-1]:g}])")


