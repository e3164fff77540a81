"""Helpers of the explicit-time tests: test models generated once per session, scipy DOP853
references."""

from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

from lagrange_gen.codegen import generate_model
from lagrange_gen.run.loader import import_generated

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent


def generate(path, out_dir, methods=None):
    """Import the module generated from model file ``path`` into out_dir."""
    return import_generated(generate_model(Path(path), out_dir, methods=methods).path)


def dop853(f, y0, t_end, t0=0.0, rtol=1e-12, atol=1e-12):
    """y(t_end) of y' = f(t, y) by scipy's DOP853."""
    sol = solve_ivp(f, (t0, t_end), np.asarray(y0, float), method="DOP853", rtol=rtol, atol=atol)
    assert sol.success, sol.message
    return sol.y[:, -1]


def generated_rhs(mod, p):
    """y' = (v, qdd) from the generated accelerations (forward dynamics)."""
    n = mod.N_COORDS

    def f(t, y):
        return np.concatenate((y[n:], mod.accelerations(y[:n], y[n:], t, p)))
    return f
