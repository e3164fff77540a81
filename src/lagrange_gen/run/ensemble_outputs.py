"""The output arrays of an ensemble and the call of the glue ``ensemble_<method>`` on a slice of
its members: what a local run (ensemble) and a Dask worker (ensemble_dask) share; the finished
result as a pandas frame and as a .npz file (the layout of a Trajectory's, run/trajectory_io.py)."""

from __future__ import annotations

import numpy as np

from ..errors import LagrangeGenError
from ..steppers.core.layout import N_STATS, last_size


def allocate_outputs(M, rows, n, n_saved):
    """Outputs, NaN until written (rows after a member's failure stay NaN); row 0 of the saved
    fields is the state a member's method starts from (an element's plastic strain or friction
    force), 0 as in simulate unless set (a constrained start's multipliers)."""
    extra = np.full((M, rows, n_saved), np.nan)
    extra[:, 0] = 0.0
    return dict(q=np.full((M, rows, n), np.nan), v=np.full((M, rows, n), np.nan),
                stats=np.full((M, rows, N_STATS), np.nan), extra=extra,
                last=np.zeros((M, last_size(n, n_saved))), status=np.zeros((M, 3), np.int64))


def member_args(q, v, p, t0, h, n_steps, save_every, config, out, members):
    """The arguments of ensemble_<method> for the members (a slice)."""
    s = members
    return (q[s], v[s], t0, h, n_steps, save_every, p[s], config, out["q"][s], out["v"][s],
            out["stats"][s], out["extra"][s], out["last"][s], out["status"][s])


def run_members(run, q, v, p, t0, h, n_steps, save_every, config, out, members):
    run(*member_args(q, v, p, t0, h, n_steps, save_every, config, out, members))


def dataframe(result):
    """The long frame of an EnsembleResult (M members, S saved rows): M S rows, member-major;
    columns member, the parameters, t, the coordinates, their velocities (name_dot), energy."""
    try:
        import pandas as pd
    except ImportError:
        raise LagrangeGenError("EnsembleResult.to_dataframe needs pandas: pip install "
                               "'lagrange-gen[dataframe]'") from None
    M, S = result.q.shape[:2]
    columns = {"member": np.repeat(np.arange(M), S)}
    for j, name in enumerate(result.param_names):
        columns[name] = np.repeat(result.params[:, j], S)
    columns["t"] = np.tile(result.t, M)
    for i, name in enumerate(result.coords):
        columns[name] = result.q[:, :, i].ravel()
    for i, name in enumerate(result.coords):
        columns[f"{name}_dot"] = result.v[:, :, i].ravel()
    columns["energy"] = result.energy.ravel()
    return pd.DataFrame(columns)


def write_ensemble(result, path):
    """Write every field of an EnsembleResult to ``path`` (.npz; read_ensemble reads it back)."""
    from .trajectory_io import ENSEMBLE, field_arrays, save_fields
    arrays, meta = field_arrays(result, ENSEMBLE)
    save_fields(path, meta, arrays)


def read_ensemble(cls, path):
    """The EnsembleResult (class ``cls``) written by write_ensemble; LagrangeGenError naming the
    file when it cannot be read, holds a Trajectory, or its fields are damaged."""
    from .trajectory_io import ENSEMBLE, from_fields, load_fields
    data = load_fields(path, ENSEMBLE)
    try:
        result = from_fields(cls, data)
        # JSON keys are text: the failure messages are keyed by member index
        result.messages = {int(i): text for i, text in result.messages.items()}
    except (ValueError, KeyError, TypeError, IndexError, AttributeError) as exc:
        first = (str(exc).splitlines() or [""])[0]
        raise LagrangeGenError(f"{path}: not an ensemble written by lagrange-gen (its metadata "
                               f"or arrays are damaged: {type(exc).__name__}: {first})") from None
    M, S = len(result.params), len(result.t)
    for name in ("q", "v", "energy"):
        if np.shape(getattr(result, name))[:2] != (M, S):
            raise LagrangeGenError(f"{path}: {name} has shape {np.shape(getattr(result, name))}"
                                   f", not ({M}, {S}, ...) for {M} members and {S} times")
    return result
