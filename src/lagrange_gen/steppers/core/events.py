"""Events: the zero crossings of the model's event functions g_k(q, v, t), located inside a step.

A model declares its events (``Model(events={name: g or Event(g, terminal=, direction=)})``);
the generated module has the kernel ``events(q, v, t, p, out)`` (out (N_EVENTS,)) and the
constants N_EVENTS, EVENT_NAMES, EVENT_TERMINAL (bool), EVENT_DIRECTION (+1 rising, -1 falling,
0 both), also when the model has none (N_EVENTS = 0, an empty kernel).

How a step loop uses this module (run_loop.run_loop for the fixed-step methods; the adaptive loop
the same way with its dense output as ``interp``), everything under ``if kern.N_EVENTS > 0``,
so that on a model without events LLVM removes it from the loop (no work, no allocation)::

    ew = events.workspace(kern, n)
    events.start(kern, ew, q, v, t0, p)                  # g at the initial state
    ... after each accepted step from t_a to t_b, state (q, v) at t_b:
    if events.crossed(kern, ew, q, v, t_b, p):          # g at t_b; a sign change to locate?
        <make the interpolant of the step ready>
        n_events, stop = events.locate(interp, iws, kern, ew, p, t_a, t_b, out_events, n_events)
        if stop: the run ends at t = ew.stop[0] with state (ew.q, ew.v)
    events.advance(ew)

A crossing of event k in a step: g_k goes from < 0 at t_a to >= 0 at t_b (rising, +1) or from
> 0 to <= 0 (falling, -1), in the order of integration (so also for h < 0); a g_k that starts
a step at exactly 0 does not cross in that step (the crossing was recorded where it reached 0).
Two crossings of one g_k inside one step cancel and are not seen: the step must resolve them.
Only the directions EVENT_DIRECTION allows are recorded. The crossing time is refined on the
interpolant of the step (``interp.interpolate(iws, t, q_out, v_out)``: hermite.py for the
fixed-step methods) by the Illinois variant of regula falsi to a bracket of
ROOT_RTOL |t_b - t_a| + 4 eps |t|. The crossings of a step are recorded in time order, each as
a row [t, k, direction, q (n), v (n)] of out_events (E, 3 + 2n) while it has room (more are
counted, not written: the driver compares n_events with E); the first terminal one ends the
step (later crossings of the step are not recorded).
"""

import sys
import warnings
from collections import namedtuple

import numpy as np
from ...jit.cache import njit

from . import layout
from .options import FAST

#: Relative (to the step) width of the bracket the crossing time is refined to.
ROOT_RTOL = 1e-12
#: Iteration cap of the refinement (Illinois converges superlinearly: about 10 are needed).
ROOT_MAX_ITER = 100
#: Unit roundoff of float64: the bracket cannot close below a few of it relative to |t|.
EPS = float(np.finfo(np.float64).eps)

#: g at the start and end of the step and at a trial time (N_EVENTS,); the located crossing
#: times t_cross (N_EVENTS,) (NaN: none) and directions sense (N_EVENTS,); the interpolated
#: state q, v (n,); stop (1,): the time of the terminal event that ended the run.
Workspace = namedtuple("Workspace", "g_prev g_new g_try t_cross sense q v stop")


@njit
def workspace(kern, n):
    """Allocated once per run by the step loop."""
    ne = kern.N_EVENTS
    return Workspace(np.zeros(ne), np.zeros(ne), np.zeros(ne), np.zeros(ne),
                     np.zeros(ne, np.int64), np.zeros(n), np.zeros(n), np.zeros(1))


@njit(**FAST)
def start(kern, ew, q, v, t, p):
    """g at the initial state."""
    kern.events(q, v, t, p, ew.g_prev)


@njit(**FAST)
def crossing(g_a, g_b, wanted):
    """+1 (rising) or -1 (falling) when g goes from g_a to g_b across zero in a direction
    ``wanted`` allows (+1, -1, or 0: both), else 0. NaN never crosses."""
    if g_a < 0.0 and g_b >= 0.0:
        sense = 1
    elif g_a > 0.0 and g_b <= 0.0:
        sense = -1
    else:
        return 0
    return sense if wanted == 0 or wanted == sense else 0


@njit(**FAST)
def crossed(kern, ew, q, v, t, p):
    """Evaluate g at the end of a step (q, v at t) into g_new; True when some event crossed."""
    kern.events(q, v, t, p, ew.g_new)
    for k in range(ew.g_new.shape[0]):
        if crossing(ew.g_prev[k], ew.g_new[k], kern.EVENT_DIRECTION[k]) != 0:
            return True
    return False


@njit(**FAST)
def advance(ew):
    """The end of this step is the start of the next."""
    for k in range(ew.g_new.shape[0]):
        ew.g_prev[k] = ew.g_new[k]


@njit(**FAST)
def event_values(kern, iws, q, v, t, p, out):
    """The model's event functions at (q, v, t) into out (N_EVENTS,): what ``refine`` roots when
    this module is its ``source``."""
    kern.events(q, v, t, p, out)


@njit(**FAST)
def g_at(interp, iws, source, kern, ew, p, k, t):
    """g_k at time t of the step, on the interpolant (leaves the state in ew.q, ew.v); the
    values come from ``source.event_values(kern, iws, q, v, t, p, out)``."""
    interp.interpolate(iws, t, ew.q, ew.v)
    source.event_values(kern, iws, ew.q, ew.v, t, p, ew.g_try)
    return ew.g_try[k]


@njit(**FAST)
def refine(interp, iws, source, kern, ew, p, k, t_a, g_a, t_b, g_b):
    """The crossing time of g_k in [t_a, t_b] (g_a, g_b of opposite signs or g_b = 0) by the
    Illinois method: regula falsi whose retained end has its g halved when it is retained twice,
    so that the bracket closes from both sides (superlinear, about 10 evaluations). ``source``
    is a module giving the values, ``event_values(kern, iws, q, v, t, p, out)``: this module for
    the model's events; dop853_impacts for its contact switching functions."""
    if g_b == 0.0:
        return t_b
    tol = ROOT_RTOL * abs(t_b - t_a) + 4.0 * EPS * max(abs(t_a), abs(t_b))
    kept = 0                   # which end was retained last: -1 a, +1 b
    t = t_b
    for _ in range(ROOT_MAX_ITER):
        if abs(t_b - t_a) <= tol:
            break
        t = t_b - g_b * (t_b - t_a) / (g_b - g_a)
        if not (min(t_a, t_b) < t < max(t_a, t_b)):
            t = 0.5 * (t_a + t_b)          # rounding put the secant point on an end
        g = g_at(interp, iws, source, kern, ew, p, k, t)
        if g == 0.0:
            return t
        if (g < 0.0) == (g_b < 0.0):       # the root is between t_a and t: t replaces t_b
            t_b, g_b = t, g
            if kept == -1:
                g_a *= 0.5
            kept = -1
        else:
            t_a, g_a = t, g
            if kept == 1:
                g_b *= 0.5
            kept = 1
    return t_b if abs(g_b) <= abs(g_a) else t_a


@njit(**FAST)
def record(kern, ew, k, t, out_events, n_events):
    """Row n_events of out_events <- [t, k, direction, q, v] (state in ew.q, ew.v) if there
    is room; returns n_events + 1."""
    if n_events < out_events.shape[0]:
        n = ew.q.shape[0]
        out_events[n_events, layout.EV_T] = t
        out_events[n_events, layout.EV_INDEX] = k
        out_events[n_events, layout.EV_DIRECTION] = ew.sense[k]
        v0 = layout.ev_v_at(n)
        for i in range(n):
            out_events[n_events, layout.EV_Q + i] = ew.q[i]
            out_events[n_events, v0 + i] = ew.v[i]
    return n_events + 1


@njit(**FAST)
def locate(interp, iws, kern, ew, p, t_a, t_b, out_events, n_events):
    """Locate and record the crossings of the step [t_a, t_b] (g_prev at t_a, g_new at t_b)
    in time order on the interpolant ``interp.interpolate(iws, ...)``; returns (n_events,
    stopped). stopped: a terminal event ended the step at ew.stop[0], with the state there in
    ew.q, ew.v (the row of that event is recorded)."""
    ne = ew.g_new.shape[0]
    for k in range(ne):
        ew.sense[k] = crossing(ew.g_prev[k], ew.g_new[k], kern.EVENT_DIRECTION[k])
        ew.t_cross[k] = np.nan
        if ew.sense[k] != 0:
            ew.t_cross[k] = refine(interp, iws, _THIS, kern, ew, p, k, t_a, ew.g_prev[k], t_b,
                                   ew.g_new[k])
    while True:
        first, s_first = -1, np.inf
        for k in range(ne):        # earliest along the integration (t_b may be < t_a)
            s = (ew.t_cross[k] - t_a) / (t_b - t_a)
            if s < s_first:        # NaN (done or no crossing) never compares less
                first, s_first = k, s
        if first < 0:
            return n_events, False
        t = ew.t_cross[first]
        ew.t_cross[first] = np.nan
        interp.interpolate(iws, t, ew.q, ew.v)
        n_events = record(kern, ew, first, t, out_events, n_events)
        if kern.EVENT_TERMINAL[first]:
            ew.stop[0] = t
            return n_events, True


# This module as the ``source`` of refine (modules, not dispatchers, are passed to jitted code).
_THIS = sys.modules[__name__]


def events_table(module, out_events, n_events):
    """The located events of a run as a structured array (one row per event, in time order):
    fields t (float), name (str, EVENT_NAMES), direction (+1 rising, -1 falling), q (n,),
    v (n,). out_events (E, 3 + 2n) as filled by the step loop, n_events the count it returned.
    When n_events > E (more events were located than out_events could hold) the first E are
    returned with a RuntimeWarning naming both counts: the driver should rather check
    n_events > E itself and say what to do."""
    names = tuple(getattr(module, "EVENT_NAMES", ()))
    n = module.N_COORDS
    rows = np.asarray(out_events)[:n_events]
    if n_events > rows.shape[0]:
        warnings.warn(f"{module.NAME}: {n_events} events were located, only the first "
                      f"{rows.shape[0]} were kept", RuntimeWarning, stacklevel=2)
    dtype = [("t", np.float64), ("name", f"U{max([1] + [len(s) for s in names])}"),
             ("direction", np.int8), ("q", np.float64, (n,)), ("v", np.float64, (n,))]
    table = np.zeros(rows.shape[0], dtype=dtype)
    table["t"], index, table["direction"], table["q"], table["v"] = layout.event_rows(rows, n)
    table["name"] = [names[int(k)] for k in index]
    return table
