"""Per-member inputs of an ensemble (lagrange_gen.ensemble): q0, v0 and parameters, and the grid
helper. Each failure is one SimulationError line naming the input.

M, the member count, comes from the inputs given per member (a leading member axis): q0 or v0
(M, n), a parameter array (M,) in the params dict, or a parameter table (M, n_params); they must
agree. Inputs given once, q0 or v0 (n,) and scalar parameters, are shared by every member.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import SimulationError
from .memory import available_memory
from .params import resolve_params


def grid(**axes):
    """{name: (K,) array} over the Cartesian product of the named axes (first name varies
    slowest), K = the product of their lengths: ``grid(k=np.linspace(1, 10, 5), c=[0, 0.1])``
    gives 10 members, usable as ``params=`` of lagrange_gen.ensemble."""
    if not axes:
        raise SimulationError("grid needs at least one named axis, e.g. grid(k=[1, 2, 3])")
    values = {}
    for name, axis in axes.items():
        arr = np.asarray(axis, dtype=np.float64).reshape(-1)
        if not arr.size:
            raise SimulationError(f"grid axis {name!r} is empty")
        values[name] = arr
    points = math.prod(arr.size for arr in values.values())
    need = 2 * points * len(values) * 8          # the columns and meshgrid's copies
    free = available_memory()
    if free is not None and need > free:
        sizes = " x ".join(str(arr.size) for arr in values.values())
        raise SimulationError(f"grid of {sizes} = {points} points needs {need / 1e9:.3g} GB of "
                              f"memory and {free / 1e9:.3g} GB is available; use fewer values "
                              f"per axis")
    columns = np.meshgrid(*values.values(), indexing="ij")      # first axis varies slowest
    return {name: np.ascontiguousarray(col.reshape(-1)) for name, col in zip(values, columns)}


def member_count(module, q0, v0, params):
    """M from the inputs given per member (1 when all are shared); SimulationError when two of
    them disagree, naming both."""
    counts = {}
    for name, value in (("q0", q0), ("v0", v0)):
        if value is not None and np.ndim(value) == 2:
            counts[name] = np.shape(value)[0]
    if isinstance(params, dict):
        for name, value in params.items():
            if np.ndim(value) == 1:
                counts[f"params[{name!r}]"] = np.shape(value)[0]
            elif np.ndim(value) > 1:
                raise SimulationError(f"{module.NAME}: params[{name!r}] must be a number or a "
                                      f"(M,) array, got shape {np.shape(value)}")
    elif params is not None and np.ndim(params) == 2:
        counts["params"] = np.shape(params)[0]
    if len(set(counts.values())) > 1:
        listed = ", ".join(f"{k} has {v}" for k, v in counts.items())
        raise SimulationError(f"{module.NAME}: the per-member inputs disagree on the member "
                              f"count: {listed}")
    return next(iter(counts.values()), 1)


def member_states(module, name, value, M):
    """q0 or v0 as a C-contiguous (M, n) float64 array (shared (n,) repeated; None: zeros)."""
    n = module.N_COORDS
    if value is None:
        return np.zeros((M, n))
    try:
        arr = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise SimulationError(f"{name} must be an array of numbers, (n,) or (M, n)") from None
    if arr.ndim not in (1, 2) or arr.shape[-1] != n:
        raise SimulationError(f"{name} has shape {arr.shape}; expected ({n},) or (M, {n}) for "
                              f"the coordinates ({', '.join(module.COORDS)})")
    bad = np.argwhere(~np.isfinite(arr))
    if bad.size:
        where = f"member {bad[0][0]}" if arr.ndim == 2 else "the shared value"
        raise SimulationError(f"{name} contains a non-finite value ({where})")
    return np.ascontiguousarray(np.broadcast_to(arr, (M, n)))


def member_params(module, params, M):
    """The parameter table (M, n_params) float64: defaults, shared values and per-member
    columns, checked by params.resolve_params (names, frozen, missing) and for finiteness."""
    names, frozen = list(module.PARAMS), getattr(module, "FROZEN", None)
    if params is None or isinstance(params, dict):
        given = dict(params or {})
        first = {k: (np.asarray(v).reshape(-1)[0] if np.ndim(v) == 1 and np.size(v) else v)
                 for k, v in given.items()}
        base = resolve_params(names, module.DEFAULTS, first, model=module.NAME, frozen=frozen)
        table = np.repeat(base[None, :], M, axis=0)
        for key, value in given.items():
            if np.ndim(value) == 1:
                column = _finite_column(module, f"params[{key!r}]", value)
                table[:, names.index(key)] = column
        return np.ascontiguousarray(table)
    try:
        table = np.asarray(params, dtype=np.float64)
    except (TypeError, ValueError):
        raise SimulationError(f"{module.NAME}: params must be a dict or an (M, n_params) "
                              f"array of numbers") from None
    if table.ndim == 1:
        base = resolve_params(names, module.DEFAULTS, table, model=module.NAME, frozen=frozen)
        return np.ascontiguousarray(np.repeat(base[None, :], M, axis=0))
    if table.ndim != 2 or table.shape[1] != len(names):
        raise SimulationError(f"{module.NAME}: params has shape {table.shape}; expected "
                              f"(M, {len(names)}) in PARAMS order ({', '.join(names)})")
    _finite_column(module, "params", table)
    return np.ascontiguousarray(table)


def _finite_column(module, name, value):
    try:
        arr = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise SimulationError(f"{module.NAME}: {name} must be numbers") from None
    bad = np.argwhere(~np.isfinite(arr))
    if bad.size:
        raise SimulationError(f"{module.NAME}: {name} is not finite for member {bad[0][0]} "
                              f"({arr[tuple(bad[0])]!r}); give finite numbers")
    return arr
