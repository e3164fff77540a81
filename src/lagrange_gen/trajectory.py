"""The result of lagrange_gen.simulate: saved states, energies, Newton statistics, writers.

    traj = simulate(...); traj.to_npz("traj.npz"); traj.to_csv("traj.csv"); traj.plot("traj.png")
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np


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
    saved: dict = field(default_factory=dict)   # {field name: (S, width)}: the method's SPEC.saved
    element_names: tuple = ()
    constraint_names: tuple = ()
    warnings: list = field(default_factory=list)   # one line each (also issued as Python warnings)
    events: tuple = ()          # located events (steppers/events.py events_table), in time order
    step_counts: dict = field(default_factory=dict)  # adaptive runs: accepted, rejected, evaluations

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
        return None if phi is None else phi[:, 0]

    @property
    def velocity_constraint_error(self):
        """(S,): max_i |(J(q) v)_i| at each saved state; None for a run without constraints."""
        jv = self.saved.get("velocity_constraint_error")
        return None if jv is None else jv[:, 0]

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

    def to_npz(self, path):
        """Write every array and the metadata to a .npz file."""
        _parent(path)
        saved = {name: (a[:, 0] if a.shape[1] == 1 else a) for name, a in self.saved.items()}
        saved.setdefault("element_state", self.element_state)
        saved.setdefault("multipliers", self.multipliers)
        np.savez(path, t=self.t, q=self.q, v=self.v, energy=self.energy,
                 newton_iters=self.newton_iters, newton_residual=self.newton_residual,
                 method=self.method, h=self.h, model=self.model, coords=np.array(self.coords),
                 param_names=np.array(list(self.params)),
                 param_values=np.array(list(self.params.values()), dtype=float),
                 n_steps=self.n_steps, element_names=np.array(self.element_names, dtype=str),
                 constraint_names=np.array(self.constraint_names, dtype=str), **saved)

    def to_csv(self, path):
        """Write one row per saved state: t, coordinates, velocities, energy, newton_iters and
        the method's saved fields (a field of width w > 1 as name_0..name_w-1; for a constrained
        method lam_0..lam_m-1, constraint_error, velocity_constraint_error)."""
        header = ["t", *self.coords, *(f"{c}_dot" for c in self.coords), "energy", "newton_iters"]
        data = np.column_stack([self.t, self.q, self.v, self.energy, self.newton_iters])
        short = {"multipliers": "lam"}
        for name, values in self.saved.items():
            stem = short.get(name, name)
            header += [stem] if values.shape[1] == 1 and name not in short else [
                f"{stem}_{i}" for i in range(values.shape[1])]
            data = np.column_stack([data, values])
        _parent(path)
        np.savetxt(path, data, delimiter=",", header=",".join(header), comments="", fmt="%.17g")

    def plot(self, path):
        """Figure (matplotlib Agg; format from the suffix, e.g. .png): coordinates vs t, and the
        energy error E - E0 vs t."""
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
        try:
            _parent(path)
            fig.savefig(path, dpi=110)
        finally:
            plt.close(fig)

    def __repr__(self):
        return (f"Trajectory({self.model}, {self.method}, h={self.h:g}, steps={self.n_steps}, "
                f"saved={len(self.t)}, t=[{self.t[0]:g}, {self.t[-1]:g}])")


def _parent(path):
    Path(path).parent.mkdir(parents=True, exist_ok=True)
