"""Helpers of the constraint tests: generated models, consistent initial states, references.

No conftest.py here on purpose (pytest would import it under the same module name as the
top-level one); test modules import from this module instead.

Generated modules go to one directory per user and checkout under the system temp dir (per
checkout: two clones' model files define the same model names, and lagrange-gen refuses to
overwrite a module generated from another model file) and are reused across test sessions: generate_model rewrites a module only when its KEY changes (model, generator or
stepper sources), so numba's on-disk cache of the run_<method> glue stays valid and a re-run
skips about a minute of compilation; a changed stepper regenerates the module and recompiles.
"""

import getpass
import hashlib
import tempfile
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

from lagrange_gen.codegen import generate_model
from lagrange_gen.run.loader import import_generated

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent
_CHECKOUT = hashlib.sha256(str(ROOT).encode()).hexdigest()[:10]
GEN_DIR = Path(tempfile.gettempdir()) / f"lagrange_gen_constraint_tests_{getpass.getuser()}_{_CHECKOUT}"
_MODULES = {}


def generated_model(stem):
    """Model stem (models/ or tests/constraints/models/) -> imported generated module."""
    if stem not in _MODULES:
        path = ROOT / "models" / f"{stem}.py"
        if not path.is_file():
            path = HERE / "models" / f"{stem}.py"
        _MODULES[stem] = import_generated(generate_model(path, GEN_DIR).path)
    return _MODULES[stem]


def params(mod, **given):
    """Parameter vector in PARAMS order: defaults overridden by ``given``."""
    values = dict(zip(mod.PARAMS, mod.DEFAULTS))
    values.update(given)
    return np.array([values[name] for name in mod.PARAMS], dtype=np.float64)


def pendulum_state(theta, omega, l=1.0):
    """Cartesian (q, v) of the pendulum at angle theta from the downward vertical, rate omega."""
    q = np.array([l * np.sin(theta), -l * np.cos(theta)])
    v = np.array([l * np.cos(theta), l * np.sin(theta)]) * omega
    return q, v


def one_angle_pendulum(theta0, omega0, t, g=9.81, l=1.0):
    """(theta, omega) at the times t (k,) of theta'' = -g/l sin(theta), DOP853 at 1e-13."""
    sol = solve_ivp(lambda _, y: [y[1], -g / l * np.sin(y[0])], (0.0, float(np.max(t))),
                    [theta0, omega0], method="DOP853", rtol=1e-13, atol=1e-13, t_eval=t)
    assert sol.success
    return sol.y[0], sol.y[1]


def four_bar_state(th1, omega1, a=1.0, b=3.0, c=2.5, d=3.0):
    """A consistent (q, v) of models/four_bar.py with crank angle th1 and crank rate omega1: the
    coupler and rocker angles close the loop (elbow-up branch), the rates solve J v = 0."""
    ax, ay = a * np.cos(th1), a * np.sin(th1)
    # Rocker tip P: |P - A_tip| = b, |P - D| = c (intersection of two circles).
    dx, dy = d - ax, -ay
    dist = np.hypot(dx, dy)
    along = (b**2 - c**2 + dist**2) / (2 * dist)
    up = np.sqrt(b**2 - along**2)
    px = ax + along * dx / dist - up * dy / dist
    py = ay + along * dy / dist + up * dx / dist
    q = np.array([th1, np.arctan2(py - ay, px - ax), np.arctan2(py, px - d)])
    J = np.array([[-a * np.sin(q[0]), -b * np.sin(q[1]), c * np.sin(q[2])],
                  [a * np.cos(q[0]), b * np.cos(q[1]), -c * np.cos(q[2])]])
    rates = np.linalg.solve(J[:, 1:], -J[:, 0] * omega1)
    return q, np.array([omega1, rates[0], rates[1]])
