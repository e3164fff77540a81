"""The state of a step API (run/stepper.py, ``lg.Stepper``) and the compiled calls on it.

A Stepper holds the method's arrays (q, v, the momentum, p, the clock [t0, steps done, t, h],
[iterations, residual]), its settings and workspace, and the kernel table of its model
(jit/portable.kernel_table), in one numba structref: Python passes one object per call, as
it passed the instance of a jitclass, but a structref's type can be kept in numba's on-disk
cache, and the table's type is the same for every model. So the portable glue of each
fixed-step method (codegen/glue.py: stepper_new_<method>, stepper_prepare_<method>,
stepper_step_<method>) is compiled once per installation for every model, and a Stepper in a
new process compiles nothing.
"""

from __future__ import annotations

import numpy as np

from ...jit import njit
from ...jit.api import overload, structref, types
from .options import fast_loop
from .state_checks import check_state

__all__ = ["StepperStateType", "StepperState", "make_workspace", "new_stepper_state", "prepare_state",
           "step_state"]

#: The fields of a Stepper's state, in order (the step h is clock[3], so that Python may set it
#: between calls).
FIELDS = ("kern", "q", "v", "mom", "p", "extra", "clock", "info", "settings", "ws", "first")


@structref.register
class StepperStateType(types.StructRef):
    """numba type of a StepperState: its fields' types (FIELDS), literal types made plain."""

    def preprocess_fields(self, fields):
        return tuple((name, types.unliteral(typ)) for name, typ in fields)


class StepperState(structref.StructRefProxy):
    """A Stepper's state as Python holds it (opaque: run/stepper.py keeps its own references
    to the arrays, which the state shares)."""


structref.define_boxing(StepperStateType, StepperState)


@njit
def make_workspace(method, kern, n):
    """The workspace of ``method`` (a stepper module) on the kernel table ``kern`` for n
    coordinates: handed to Python, which keeps it (its arrays are the state's)."""
    return method.workspace(kern, n)


def new_stepper_state(kern, q, v, p, clock, info, settings, ws, first):
    """The StepperState on the kernel table ``kern`` (jitted: see the overload): q, v (n,),
    p (n_params,), clock [t0, 0, t0, h], info (2,), the workspace ws (make_workspace), all
    shared with the caller; the momentum zero."""


@overload(new_stepper_state)
def _new_stepper_state(kern, q, v, p, clock, info, settings, ws, first):
    vector = types.Array(types.float64, 1, "C")          # the momentum and extra, made here
    state_type = StepperStateType(fields=list(zip(FIELDS, (kern, q, v, vector, p, vector, clock,
                                                         info, settings, ws, first))))

    def impl(kern, q, v, p, clock, info, settings, ws, first):
        state = structref.new(state_type)
        state.kern, state.q, state.v, state.mom, state.p = kern, q, v, np.zeros(q.shape[0]), p
        state.extra, state.clock, state.info, state.settings = np.zeros(0), clock, info, settings
        state.ws, state.first = ws, first
        return state
    return impl


@njit
def prepare_state(method, state):
    """The method's prepare at the state's time (after a change of the inputs): its status."""
    return method.prepare(state.kern, state.q, state.v, state.mom, state.clock[2], state.p,
                          state.settings, state.ws, state.extra)


@njit
def step_state(method, state, u, k):
    """k steps with the inputs held at u (n_inputs,) written into the last entries of p (an
    empty u keeps them; a changed one runs prepare first): 0, or the status that ended them."""
    changed = False
    for j in range(u.shape[0]):
        changed |= state.p[state.first + j] != u[j]
        state.p[state.first + j] = u[j]
    if changed:
        status = prepare_state(method, state)
        if status != 0:
            return status
    return _advance(method, state.kern, state.q, state.v, state.mom, state.p, state.settings,
                    state.ws, state.extra, state.clock, state.info, k)


@fast_loop
def _advance(method, kern, q, v, mom, p, settings, ws, extra, clock, info, k):
    """k steps; clock = [t0, steps done, t, h]; info = [iterations, residual]. Apart from the
    state's reads, without reference counting: counting every array a step touches costs as
    much as the step itself (options.fast_loop)."""
    h = clock[3]
    for _ in range(k):
        t = clock[0] + clock[1] * h
        status, iters, resid = method.step(kern, q, v, mom, t, h, p, settings, ws, extra)
        info[0] = iters
        info[1] = resid
        if status != 0:
            return status
        clock[1] += 1.0
        clock[2] = clock[0] + clock[1] * h
        status = check_state(q, v, settings.blowup_bound)
        if status != 0:
            return status
    return 0
