"""Least-squares identification of a model's parameters from measured coordinates, with the exact
Jacobian of the simulated coordinates from forward sensitivities (run/sensitivities.py).

    fit = lg.fit("models/double_pendulum.py", "midpoint", t=t, q=q_measured, q0=q0, v0=v0,
                 h=1e-3, fit=["m2", "l2"])
    fit.params["l2"], fit.cost, fit.covariance, fit.iterations

Each evaluation is one simulate run with sensitivities to the fitted names (their columns of
d q/d theta at the measured times are the residuals' Jacobian); scipy.optimize.least_squares
(trust region reflective) drives the iteration. The measured times must lie on the step grid
t0 + k h (the simulated states are the method's own, not interpolated).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import IdentificationError


@dataclass
class Fit:
    """params: every parameter of the model, the fitted ones at their estimates; fitted: the
    fitted names; cost: 1/2 sum of squared residuals at the estimate; rms: the residuals' root
    mean square; covariance (k, k): sigma^2 (J^T J)^-1 with sigma^2 = 2 cost / (m - k), the
    estimates' covariance for independent equal-variance noise (rows, columns in ``fitted``
    order); standard_errors (k,): its diagonal's square roots; iterations: Jacobian
    evaluations (one sensitivity run each); evaluations: residual evaluations; success and
    message: scipy's."""

    params: dict
    fitted: tuple
    cost: float
    rms: float
    covariance: np.ndarray
    iterations: int
    evaluations: int
    success: bool
    message: str
    standard_errors: np.ndarray = field(default=None)


def _grid_rows(t, t0, h):
    """Step indices (m,) of the measured times on the grid t0 + k h; IdentificationError when a
    time is off the grid or before t0."""
    steps = (t - t0) / h
    rows = np.rint(steps).astype(np.int64)
    off = np.abs(steps - rows) > 1e-6
    if off.any() or (rows < 0).any():
        bad = float(t[np.argmax(off | (rows < 0))])
        raise IdentificationError(f"fit: the measured time {bad!r} is not on the step grid "
                                  f"t0 + k h (t0 = {t0}, h = {h}); resample the data or choose h")
    return rows


def fit(module_or_path, method="midpoint", *, t, q, q0, v0, h, params=None, fit, t0=0.0,
        bounds=None, max_iterations=50, out_dir=None, **settings) -> Fit:
    """Fit the parameters named in ``fit`` so that the coordinates simulated by ``method`` with
    step h from (q0, v0) at t0 match ``q`` (m, n) measured at times ``t`` (m,) in least squares.

    params: the starting values (a dict; the others stay at these values or the defaults).
    out_dir: where a model file is generated (as simulate's; with sensitivities).
    bounds: {name: (low, high)} for fitted names (default unbounded). settings: the method's
    (e.g. newton_tol). IdentificationError in one line for NaN data, shapes that do not fit,
    times off the step grid or a name that is not a parameter of the model."""
    from scipy.optimize import least_squares

    from ..run.simulate import load_module, simulate
    module = load_module(module_or_path, out_dir, method=method, sensitivities=True)
    names = [fit] if isinstance(fit, str) else list(fit)
    unknown = [name for name in names if name not in module.PARAMS]
    if unknown or not names:
        raise IdentificationError(f"fit: {module.NAME} has no parameter {unknown[0]!r} (known: "
                                  f"{', '.join(module.PARAMS)})" if unknown else
                                  "fit: name the parameters to fit, e.g. fit=['m2']")
    t = np.asarray(t, dtype=float).ravel()
    q = np.asarray(q, dtype=float)
    n = module.N_COORDS
    if q.ndim == 1 and n == 1:
        q = q[:, None]
    if q.shape != (t.shape[0], n):
        raise IdentificationError(f"fit: q has shape {q.shape}; expected ({t.shape[0]}, {n}): "
                                  f"one row of the {n} coordinates per measured time")
    if not (np.isfinite(t).all() and np.isfinite(q).all()):
        raise IdentificationError("fit: the data hold NaN or inf (t or q); remove those samples")
    rows = _grid_rows(t, float(t0), float(h))
    t_end = float(t0) + int(rows.max()) * float(h)
    start = dict(params or {})
    defaults = dict(zip(module.PARAMS, module.DEFAULT_PARAMS.tolist()))
    x0 = np.array([float(start.get(name, defaults[name])) for name in names])
    low = np.array([(bounds or {}).get(name, (-np.inf, np.inf))[0] for name in names], float)
    high = np.array([(bounds or {}).get(name, (-np.inf, np.inf))[1] for name in names], float)
    x0 = np.clip(x0, low, high)
    memo = {}

    def run(x):
        key = x.tobytes()
        if key not in memo:
            values = {**start, **dict(zip(names, x.tolist()))}
            traj = simulate(module, method, q0, v0, t_end=t_end, h=h, t0=t0, params=values,
                            sensitivities=names, **settings)
            r = (traj.q[rows] - q).ravel()
            J = np.stack([traj.sensitivity(name)[rows, :n].ravel() for name in names], axis=1)
            memo.clear()
            memo[key] = (r, J)
        return memo[key]

    result = least_squares(lambda x: run(x)[0], x0, jac=lambda x: run(x)[1],
                           bounds=(low, high), x_scale="jac", max_nfev=max_iterations)
    r, J = run(result.x)
    m, k = r.size, len(names)
    cost = 0.5 * float(r @ r)
    sigma2 = 2 * cost / max(m - k, 1)
    try:
        covariance = sigma2 * np.linalg.inv(J.T @ J)
    except np.linalg.LinAlgError:
        covariance = np.full((k, k), math.inf)
    fitted = {**defaults, **start, **dict(zip(names, result.x.tolist()))}
    return Fit(params=fitted, fitted=tuple(names), cost=cost, rms=math.sqrt(2 * cost / m),
               covariance=covariance, iterations=int(result.njev or 0),
               evaluations=int(result.nfev), success=bool(result.success),
               message=str(result.message),
               standard_errors=np.sqrt(np.abs(np.diag(covariance))))
