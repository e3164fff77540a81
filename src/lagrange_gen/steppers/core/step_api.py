"""The state of a step API (run/stepper.py, ``lg.Stepper``) and the compiled calls on it.

A Stepper holds the method's arrays (q, v, the momentum, p, the clock [t0, steps done, t],
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

__all__ = ["StepperStateType", "StepperState", "new_stepper_state", "prepare_state", "step_state"]

#: The fields of a Stepper's state, in order.
FIELDS = ("kern", "q", "v", "mom", "p", "extra", "clock", "info", "settings", "ws", "h", "first")


@structref.register
class StepperStateType(types.StructRef):
    """numba type of a StepperState: its fields' types (FIELDS), literal types made plain."""

    def preprocess_fields(self, fields):
        return tuple((name, types.unliteral(typ)) for name, typ in fields)


class StepperState(structref.StructRefProxy):
    """A Stepper's state as Python holds it (opaque: run/stepper.py keeps its own references
    to the arrays, which the state shares)."""


structref.define_boxing(StepperStateType, StepperState)


def new_stepper_state(method, kern, q, v, p, clock, info, settings, h, first):
    """The StepperState of ``method`` (a stepper module) on the kernel table ``kern`` (jitted:
    see the overload): the method's workspace made for n = q.shape[0], the momentum zero."""


@overload(new_stepper_state)
def _new_stepper_state(method, kern, q, v, p, clock, info, settings, h, first):
    def impl(method, kern, q, v, p, clock, info, settings, h, first):
        n = q.shape[0]
        return _assemble(kern, q, v, np.zeros(n), p, np.zeros(0), clock, info, settings,
                         method.workspace(kern, n), h, first)
    return impl


def _assemble(kern, q, v, mom, p, extra, clock, info, settings, ws, h, first):
    """structref.new of the type these arguments make, every field set."""


@overload(_assemble)
def _assemble_impl(kern, q, v, mom, p, extra, clock, info, settings, ws, h, first):
    state_type = StepperStateType(fields=list(zip(FIELDS, (kern, q, v, mom, p, extra, clock, info,
                                                         settings, ws, h, first))))

    def impl(kern, q, v, mom, p, extra, clock, info, settings, ws, h, first):
        state = structref.new(state_type)
        state.kern, state.q, state.v, state.mom, state.p = kern, q, v, mom, p
        state.extra, state.clock, state.info, state.settings = extra, clock, info, settings
        state.ws, state.h, state.first = ws, h, first
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
                    state.ws, state.extra, state.clock, state.info, state.h, k)


@fast_loop
def _advance(method, kern, q, v, mom, p, settings, ws, extra, clock, info, h, k):
    """k steps; clock = [t0, steps done, t]; info = [iterations, residual]. Apart from the
    state's reads, without reference counting: counting every array a step touches costs as
    much as the step itself (options.fast_loop)."""
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
