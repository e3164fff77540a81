"""Forward sensitivities of a fixed-step run: simulate(..., sensitivities=["l2", "q0", "v0"]).

    traj = lg.simulate("models/double_pendulum.py", "midpoint", q0, v0, t_end=5, h=1e-3,
                       sensitivities=["l2", "q0"])
    traj.sensitivity("l2")      # (S, 2n): d(q, v)/d l2 at each saved row
    traj.sensitivity("q0")      # (S, 2n, n): d(q, v)/d q0

The derivative is that of the discrete map the method computes (discretise-then-differentiate:
steppers/sensitivity/), so it equals central differences of simulate's own runs as their
difference step shrinks, whatever h. The run takes the method's step and its tangent step
together in one compiled loop (steppers/sensitivity/core.py), on the portable kernel table
(compiled once per method for every model, kept in numba's cache); the module needs the
parameter derivatives of its kernels, generated when asked (a model file is regenerated with
them, ``lagrange-gen --sensitivities``).
"""

from __future__ import annotations

import importlib
import time

import numpy as np

from ..errors import SimulationError
from ..jit.compile_notice import first_use_notice
from ..steppers.core import status as st
from ..steppers.sensitivity import SENSITIVITY_METHODS
from .trajectory import Trajectory

#: Names of the initial-state sensitivities.
INITIAL = ("q0", "v0")


def sensitivity_columns(module, names):
    """(cols (k,) int64: the parameters' indices in p, {name: (first column, width)}, c) for the
    requested names: parameters first in the order given, then q0 (n columns), then v0 (n).
    SimulationError in one line for a name that is neither a parameter nor q0/v0."""
    if isinstance(names, str):
        names = [names]
    names = list(names)
    params, n = list(module.PARAMS), module.N_COORDS
    frozen = module.OPTIONS.get("freeze", {}) if isinstance(getattr(module, "OPTIONS", None), dict) else {}
    seen = set()
    for name in names:
        if not isinstance(name, str):
            raise SimulationError(f"simulate: sensitivities: {name!r} is not a name (a parameter "
                                  f"of {module.NAME}, q0 or v0)")
        if name in seen:
            raise SimulationError(f"simulate: sensitivities: {name!r} is asked twice")
        seen.add(name)
        if name in INITIAL or name in params:
            continue
        if name in frozen:
            raise SimulationError(f"simulate: sensitivities: parameter {name!r} of {module.NAME} "
                                  f"was frozen at generation (a constant in the kernels)")
        known = ", ".join(params + list(INITIAL))
        raise SimulationError(f"simulate: sensitivities: {module.NAME} has no parameter {name!r} "
                              f"(known: {known})")
    wanted = [name for name in names if name not in INITIAL]
    cols = np.array([params.index(name) for name in wanted], dtype=np.int64)
    layout = {name: (j, 1) for j, name in enumerate(wanted)}
    c = len(wanted)
    for name in INITIAL:
        if name in seen:
            layout[name] = (c, n)
            c += n
    return cols, layout, c


def initial_tangent(n, layout, c):
    """S0 (2n, c): zero for the parameters, the identity blocks of q0 and v0."""
    S0 = np.zeros((2 * n, c))
    for name, rows in (("q0", slice(0, n)), ("v0", slice(n, 2 * n))):
        if name in layout:
            first, width = layout[name]
            S0[rows, first:first + width] = np.eye(n)
    return S0


def check_method(method):
    """SimulationError in one line when ``method`` has no forward sensitivities."""
    if method not in SENSITIVITY_METHODS:
        raise SimulationError(f"simulate: {method} has no sensitivities (methods with "
                              f"sensitivities: {', '.join(SENSITIVITY_METHODS)})")


def check_sensitivities(module, method):
    """SimulationError in one line when ``method`` on ``module`` has no forward sensitivities."""
    check_method(method)
    if getattr(module, "N_EVENTS", 0):
        raise SimulationError(f"simulate: {module.NAME} has events; a run with sensitivities "
                              f"does not locate them (remove the events or the sensitivities)")
    from ..codegen.needs import sensitivity_needs
    missing = [name for name in sorted(sensitivity_needs(method)) if not hasattr(module, name)]
    if missing:
        from ..codegen.keys import regeneration_command_from
        command = (regeneration_command_from(module.__file__, module.MODEL_PATH,
                                             {**module.OPTIONS, "sensitivities": True})
                   if getattr(module, "MODEL_PATH", None) else "lagrange-gen MODEL --sensitivities")
        raise SimulationError(f"simulate: {module.NAME} ({module.__file__}) was generated without "
                              f"sensitivities: run `{command}`, or pass the model file")


def simulate_sensitivities(module, method, q, v, p, settings, h, t0, n_steps, save_every,
                           names) -> Trajectory:
    """The Trajectory of a fixed-step run with its sensitivities (Trajectory.sensitivity)."""
    from ..jit.portable import sensitivity_table
    check_sensitivities(module, method)
    n = module.N_COORDS
    cols, layout, c = sensitivity_columns(module, names)
    S0 = initial_tangent(n, layout, c)
    rows = n_steps // save_every + 1 + (1 if n_steps % save_every else 0)
    out_q, out_v = np.empty((rows, n)), np.empty((rows, n))
    out_S, out_stats = np.empty((rows, 2 * n, c)), np.zeros((rows, 3))
    run = importlib.import_module(f"lagrange_gen.steppers.sensitivity.{method}").run
    table = sensitivity_table(module, method)
    start = time.perf_counter()
    # the first run of a method with sensitivities compiles its loop (then numba's cache has it)
    with first_use_notice(f"the sensitivities of {method} (all models)"):
        status, done = run(table, q, v, float(t0), float(h), int(n_steps), int(save_every), p,
                           settings, cols, S0, out_q, out_v, out_S, out_stats)
    wall = time.perf_counter() - start
    if status != st.OK:
        step = max(int(done), 0)
        raise SimulationError(f"{module.NAME}: {method} with sensitivities failed at step {step} "
                              f"(t = {t0 + step * h:.6g}): {st.NAMES.get(status, status)}")
    steps = np.arange(rows) * save_every
    steps[-1] = n_steps
    t = t0 + steps * h
    sens = {}
    for name, (first, width) in layout.items():
        block = out_S[:, :, first:first + width]
        sens[name] = block[:, :, 0].copy() if name not in INITIAL else block.copy()
    return Trajectory(t=t, q=out_q, v=out_v, energy=out_stats[:, 0].copy(),
                      newton_iters=out_stats[:, 1].copy(), newton_residual=out_stats[:, 2].copy(),
                      method=method, h=float(h), model=module.NAME,
                      params=dict(zip(module.PARAMS, p.tolist())), coords=tuple(module.COORDS),
                      n_steps=int(n_steps), wall_time=wall, jit="portable",
                      settings=dict(settings._asdict()), sensitivities=sens)
