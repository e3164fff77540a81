"""The hard cases of HARD_CASES.md (4-8) as scenes: a model, a start, an end time, the fixed h of
the hard suite, and what "stable" means for the scene (used by the stability suite's search for
the largest stable h); consistent starts of the constrained models. Their closed-form solutions
are in reference.py.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.special import ellipk

from .reference import FPU_OMEGA, SEPARATRIX_K


@dataclass(frozen=True)
class Scene:
    """key, title; stem and build options of the model file; parameters; start (q0, v0); t_end;
    h (the hard suite's fixed step); h_max (where the stable-h search starts); ``stable`` names
    the predicate in STABLE."""

    key: str
    title: str
    stem: str
    params: dict
    q0: tuple
    v0: tuple
    t_end: float
    h: float
    h_max: float
    stable: str
    options: dict = field(default_factory=dict)


def oscillator_scene(compliance, b=0.1, h=0.01, t_end=10.0):
    """Case 4: m x'' + b x' + x / c = 0, m = 1, x0 = 1; tau = h / sqrt(c)."""
    return Scene(f"oscillator_c{compliance:.0e}", f"damped oscillator, c = {compliance:g}",
                 "damped_oscillator", {"m": 1.0, "c": compliance, "b": b}, (1.0,), (0.0,),
                 t_end, h, 1.0, "energy_not_growing")


def fpu_scene(t_end=200.0, h=0.01):
    r = math.sqrt(2.0)
    w = FPU_OMEGA
    q0 = ((1 - 1 / w) / r, (1 + 1 / w) / r, 0.0, 0.0, 0.0, 0.0)
    return Scene("fpu", f"FPU chain, omega = {w:g}", "fpu", {"omega": w}, q0,
                 (0.0, r, 0.0, 0.0, 0.0, 0.0), t_end, h, 0.2, "energy_not_growing")


def separatrix_scene(periods=4, h=0.01):
    """Case 6: theta'' = -sin(theta) (n_link_pendulum n = 1, m = l = g = 1), theta'(0) = 2k."""
    period = 4 * ellipk(SEPARATRIX_K**2)
    return Scene("separatrix", f"pendulum near the separatrix, k = {SEPARATRIX_K}",
                 "n_link_pendulum", {"m": 1.0, "l": 1.0, "g": 1.0}, (0.0,),
                 (2 * SEPARATRIX_K,), periods * period, h, 1.0, "libration",
                 options={"n": 1})


# ---------------------------------------------------------------- what "stable" means per scene

def _energy_not_growing(traj, scene):
    """No growth: max E - E0 <= |E0| / 2. Damping, physical or numerical, passes: whether it is
    acceptable is an accuracy question (the hard suite), not a stability one."""
    return float(np.max(traj.energy)) - traj.energy[0] <= 0.5 * abs(traj.energy[0])


def _libration(traj, scene):
    """The pendulum stays inside the separatrix: |theta| < pi throughout."""
    return float(np.max(np.abs(traj.q[:, 0]))) < math.pi


STABLE = {"energy_not_growing": _energy_not_growing, "libration": _libration}


def is_stable(traj, scene):
    return STABLE[scene.stable](traj, scene)


def four_bar_start(mod, p, th1=math.pi / 2):
    """A consistent configuration (3,) of models/four_bar.py: th1 given, th2 and th3 from the
    loop closure Phi = 0 by fsolve (from a guess on the crank-rocker's assembly branch)."""
    from scipy.optimize import fsolve
    n, m = mod.N_COORDS, mod.N_CONSTRAINTS
    phi, J, gamma = np.empty(m), np.empty((m, n)), np.empty(m)

    def residual(x):
        mod.constraints(np.array([th1, *x]), np.zeros(n), 0.0, p, phi, J, gamma)
        return phi.copy()
    x, _, ier, msg = fsolve(residual, [0.3, 1.5], full_output=True, xtol=1e-14)
    if ier != 1:
        raise RuntimeError(f"four_bar: no consistent start at th1 = {th1}: {msg}")
    return np.array([th1, *x])


def cartesian_pendulum_start(mod, p, theta=0.5):
    """(l sin theta, -l cos theta): on |x| = l."""
    l = dict(zip(mod.PARAMS, p))["l"]
    return np.array([l * math.sin(theta), -l * math.cos(theta)])


#: Consistent starts computed from the generated module: stem -> f(mod, p) -> q0 (n,).
STARTS = {"four_bar": four_bar_start, "cartesian_pendulum": cartesian_pendulum_start}


def model_start(mod):
    """A valid q0 (n,) for a module at its default parameters: STARTS, else zeros."""
    start = STARTS.get(mod.NAME)
    p = np.asarray(mod.DEFAULT_PARAMS, dtype=float)
    return start(mod, p) if start else np.zeros(mod.N_COORDS)


def start_of(scene, mod, p):
    """(q0, v0) arrays of a scene (q0 from STARTS when the scene's q0 is None)."""
    q0 = STARTS[scene.stem](mod, p) if scene.q0 is None else np.array(scene.q0, float)
    return q0, np.array(scene.v0, float)


def constrained_scenes(quick):
    """Case 7 at k = 1e6 (h omega = 10 at h = 0.01) and case 8's linkage (constrained methods)."""
    q0 = (math.sin(0.5), -math.cos(0.5))
    return [Scene("stretchable_k1e6", "stretchable pendulum, k = 1e6", "stretchable_pendulum",
                  {"k": 1e6}, q0, (0.0, 0.0), 5.0, 0.01, 0.1, "energy_not_growing"),
            Scene("four_bar", "four-bar linkage", "four_bar", {}, None, (0.0, 0.0, 0.0),
                  2.0 if quick else 10.0, 1e-3, 0.1, "energy_not_growing")]
