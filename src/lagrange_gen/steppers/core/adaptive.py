"""The run loop of the adaptive methods: error-controlled steps, output at t_eval or every step.

The generated glue of an adaptive method (codegen.glue.ADAPTIVE_GLUE_ARGS) calls::

    run_adaptive(method, kern, n_saved, n_event_fns, q0, v0, t0, t_end, p, settings, t_eval,
                 out_t, out_q, out_v, out_stats, out_extra, out_last, out_events, counters)
        -> (status, rows, n_events)

    q0, v0      (n,) state at t0;  t_end may be < t0 (integrates backwards)
    t_eval      (E,) output times, monotone in the direction of integration; E = 0: output at
                every accepted step
    out_t (S,), out_q (S, n), out_v (S, n), out_stats (S, N_STATS), out_extra (S, n_saved);
                S >= 2 (ValueError otherwise, like the buffer check of run_loop.run_loop)
    out_last    (2n + 3 + n_saved,) [t, q, v, accepted steps since the last row, last accepted
                error norm, saved fields] of the state reached (see below), or one entry
                longer: then W there in the last entry (layout.work_at)
    out_events  (E', 3 + 2n): located events (see "Events" below)
    counters    (4,) float64, in/out: [h, accepted, rejected, evaluations]. In: counters[0] =
                the first step size to try (its sign is ignored; 0: Hairer's automatic starting
                step); out: the next step size proposed, signed (pass it back in to continue).
                counters[1:] are incremented by this call: accepted steps, rejected steps
                (also those before the first accepted step, which dop853.f does not count),
                acceleration (right-hand side) evaluations.

Rows: row 0 = the state at t0 of this call. Then, with E = 0, one row per accepted step (its
end state); with E > 0, one row per t_eval value with t0 < t_eval[j] <= t_end (values <= t0
are skipped), from the method's dense output, except that a value equal to a step's end time
gets the step's end state exactly. Steps are clipped to land exactly on t_end (out_last[0] ==
t_end exactly), and the integration always runs to t_end, even after the last t_eval value.
out_stats per row: STAT_ENERGY the energy, STAT_ITERS the accepted steps since the previous
row (0 for a second t_eval value inside the same step), STAT_RESIDUAL the error norm of the
accepted step the row comes from (<= 1; 0 in row 0), STAT_WORK the work W since t0 (work.py),
continued from out_stats[0, STAT_WORK] (0 for a model without kern.WORK): the method steps
it with q, v (dop853: W' = P(q, v, t) at its stages, under its error control), a t_eval row
gets it from the dense output like q, v.

Chunks: ``rows`` rows were written. A call returns OK either complete (out_last[0] == t_end) or
with full buffers: before a step whose output would not fit, it returns the state it would have
stepped from in out_last (not necessarily a row: with t_eval it is the last step end) and the
step it would have tried in counters[0]. The driver calls again from out_last's t, q, v (its
saved fields as row 0 of out_extra, its W as out_stats[0, STAT_WORK]) with counters as
returned, fresh buffers and (with t_eval) the t_eval values not yet output; row 0 of the new call is that start state, to be
dropped (it repeats the previous call's last row or is not a requested time); the accepted
steps the previous call took after its last row (out_last[1 + 2n]) belong to the STAT_ITERS of
the new call's row 1. The continued run is bitwise the run in one call: the step sequence
depends only on the state and the proposed step at step boundaries. Exception: if even a fresh
buffer cannot hold the t_eval values one step covers, the step is shortened to end at the last
one that fits.
max_steps caps the attempted (accepted + rejected) steps of one call, not of the run.

Step-size control (Hairer, dop853.f, beta = 0): with err the method's error norm,
fac = clip(err^(1/(p+1)) / SAFETY, 1/FAC_MAX, 1/FAC_MIN), the next h = h / fac (at most
FAC_MAX times larger, at least FAC_MIN of it); a rejected step retries with
h / min(1/FAC_MIN, err^(1/(p+1)) / SAFETY), and the step accepted after a rejection may not
propose a larger one. |h| <= settings.h_max. A step is clipped to land on t_end when
t + 1.01 h passes it. A trial whose error norm is not finite (NaN/inf in its stages) is
rejected with the largest reduction, FAC_MIN.

Failures: status codes (lagrange_gen.steppers.core.status) with out_last at the state concerned, its time
in out_last[0]:
    SINGULAR_MASS          an evaluation failed; out_last = the state the step started from
                           (a stage, the dense output) or its end state (the end-point
                           evaluation of an accepted step)
    NON_FINITE, UNSTABLE   the accepted state (or the energy of a row) is non-finite / past
                           settings.blowup_bound; out_last = that state (t_eval: the row's)
    STEP_TOO_SMALL         0.1 |h| <= |t| eps (the step underflowed the time resolution, e.g.
                           a solution blowing up in finite time); NON_FINITE instead when the
                           rejections leading there were non-finite trials; out_last = state at t
    TOO_MANY_STEPS         settings.max_steps attempts in this call; out_last = state at t
``rows`` = the rows written before the failure (0: the initial state was refused).

Events (n_event_fns > 0, see events.py): after each accepted step the event functions are
evaluated at the new state; on a sign change the dense output of the step is built and the
crossing refined on ``method.interpolate``; located events go to out_events (E, 3 + 2n) rows
[t, event index, direction, q, v] while there is room (n_events counts them all). A terminal
event ends the call at the event: every-step mode saves the event state as the last row, t_eval
mode the t_eval values before it; out_last holds the event state, status OK, and out_last[0]
(the event time) is before t_end: the driver must not continue (it tells a terminal stop from
full buffers by the last recorded event). dense must run before advance (which reuses the step's stages); the interpolant stays
valid until the next dense call. Without t_eval values inside a step, dense is not called
(it costs DENSE_EVALS evaluations).

What a method module provides (dop853.py): workspace(kern, n) (a namedtuple with at least the
(n,) arrays q_new, v_new (the trial state) and q_int, v_int (interpolation) and the (1,) arrays
w, w_new (W at the current and at the trial state)), prepare(kern, q, v, t, p, settings, ws)
-> status (stage 0 at the start state), initial_step(kern, q, v, t, direction, p, settings,
ws) -> (status, |h|), attempt(kern, q, v, t, h, p, settings, ws) -> (status, err) into
ws.q_new, ws.v_new (ws.w_new), accept(kern, t_new, p, ws) -> status, dense(kern, q, v, t, h,
p, ws) -> status, interpolate(ws, t, q_out, v_out), interpolate_work(ws, t) -> W (called on
models with kern.WORK only), advance(q, v, ws) (w <- w_new too), and the constants
ERROR_EXPONENT = 1/(p+1), STAGE_EVALS, ACCEPT_EVALS, DENSE_EVALS, ROWS_PER_STEP (rows one step
may write in every-step mode).

Switches (dop853_impacts; dop853's are no-ops): after each accepted step,
switch_point(kern, ws, q, v, t, h, t_new, p, extra, counters) -> (status, switched, t_end of
the step): when switched, the step ends early at that time with the state there in ws.q_new,
ws.v_new (W in ws.w_new) and the dense output of the whole step built (the step's rows and the model's events
use it up to there); then apply_switch(kern, ws, q, v, t, p, settings, extra) -> status makes
the state the run continues from (in place: impulses, new modes) and every-step mode writes it
as a second row at the same time. apply_switch also runs once on the start state, after
prepare, before row 0 is written.

Over 300 lines with this contract: the loop, its step-size control and its two ways of saving
(t_eval rows, events) share the loop's state (t, h, the counters, the rows written), so they
stay in one module, the contract beside the code it describes.
"""

import math

import numpy as np
from ...jit.cache import njit

from . import events, layout
from .layout import STAT_WORK
from .options import FAST
from .output import save_row, write_last, write_work
from .state_checks import check_state
from .status import NON_FINITE, OK, STEP_TOO_SMALL, TOO_MANY_STEPS


SAFETY = 0.9          # Hairer's safe
FAC_MIN = 0.333       # Hairer's fac1: smallest step ratio
FAC_MAX = 6.0         # Hairer's fac2: largest step ratio
UROUND = 2.220446049250313e-16


@njit(**FAST)
def next_step(h, err, exponent, h_max, after_reject):
    """Hairer's proposal after a step of size h with error norm err <= 1 (signed result)."""
    fac = max(1.0 / FAC_MAX, min(1.0 / FAC_MIN, err ** exponent / SAFETY))
    h_new = min(abs(h / fac), h_max)
    if after_reject:
        h_new = min(h_new, abs(h))
    return math.copysign(h_new, h)


@njit(**FAST)
def retry_step(h, err, exponent):
    """The retry after a rejected step (err > 1, or NaN: then the largest reduction)."""
    shrink = err ** exponent / SAFETY
    if not shrink < 1.0 / FAC_MIN:      # also NaN
        shrink = 1.0 / FAC_MIN
    return h / shrink


@njit(**FAST)
def points_in(t_eval, j, t_new, direction, cap):
    """How many of t_eval[j:] are <= t_new (in the direction of integration), counting up to
    cap."""
    k = 0
    while j + k < t_eval.shape[0] and k < cap and (t_eval[j + k] - t_new) * direction <= 0.0:
        k += 1
    return k


@njit(inline="always")
def _save_row(kern, row, t, q, v, W, p, since, err, out_t, out_q, out_v, out_stats, extra,
              out_extra):
    """Write one output row (W the work there); False (nothing written) when the energy there
    is not finite."""
    energy = kern.energy(q, v, t, p)
    if not math.isfinite(energy):
        return False
    save_row(row, t, q, v, energy, since, err, out_t, out_q, out_v, out_stats, extra, out_extra)
    out_stats[row, STAT_WORK] = W
    return True


@njit(inline="always")
def _stop(out_last, counters, t, q, v, W, since, err, extra, h):
    """Where a call ends: out_last = [t, q, v, since, err, extra(, W)], counters[0] = h."""
    write_last(out_last, t, q, v, since, err, extra)
    write_work(out_last, q.shape[0], extra.shape[0], W)
    counters[0] = h


@njit(inline="always")
def _work_at(method, kern, ws, t):
    """W at t inside the last step, from the method's dense output (built); 0 on a model
    without kern.WORK (nothing evaluated)."""
    if kern.WORK:
        return method.interpolate_work(ws, t)
    return 0.0


@njit(inline="always")
def _first_step(method, kern, q, v, t0, t_end, p, settings, ws, counters):
    """(status, signed h) of the first attempt: counters[0], or Hairer's starting step."""
    direction = 1.0 if t_end >= t0 else -1.0
    h = abs(counters[0])
    status = OK
    if h == 0.0 and t_end != t0:
        status, h = method.initial_step(kern, q, v, t0, direction, p, settings, ws)
        counters[3] += 1
    return status, direction * min(h, settings.h_max)


@njit(inline="always")
def _room(t_eval, j, t, h, rows, size, per_step):
    """Before the first attempt of a step of size h from t: (fits, h). fits False: the rows
    this step may output do not fit (the call returns first). per_step: the rows one step may
    write in every-step mode (method.ROWS_PER_STEP). A fresh buffer (rows == 1) too small for
    the t_eval values of the step shortens h to end at the last one that fits; one too small
    for per_step rows takes the step (the rows past the end are not written)."""
    direction = 1.0 if h > 0.0 else -1.0
    k = points_in(t_eval, j, t + h, direction, size) if t_eval.shape[0] > 0 else per_step
    if rows + k <= size:
        return True, h
    if rows > 1 or t_eval.shape[0] == 0:
        return rows == 1, h
    return True, t_eval[j + size - 2] - t


@njit(inline="always")
def _output(method, kern, ws, q, v, t, h, t_new, err, p, t_eval, j, rows, since, extra,
            out_t, out_q, out_v, out_stats, out_extra, out_last, counters, built):
    """The rows of an accepted step from (q, v) at t to (ws.q_new, ws.v_new) at t_new: its end
    state, or the t_eval values it covers (dense output, built at most once; ``built``: it is
    already, and ws.q_new is no longer the end of the step it was built for). Returns
    (status, rows, j, since); on failure out_last and counters[0] are set (_stop)."""
    if t_eval.shape[0] == 0:
        if not _save_row(kern, rows, t_new, ws.q_new, ws.v_new, ws.w_new[0], p, since, err,
                         out_t, out_q, out_v, out_stats, extra, out_extra):
            _stop(out_last, counters, t_new, ws.q_new, ws.v_new, ws.w_new[0], since, err, extra,
                  h)
            return NON_FINITE, rows, j, since
        return OK, rows + 1, j, 0.0
    direction = 1.0 if h > 0.0 else -1.0
    while j < t_eval.shape[0] and (t_eval[j] - t_new) * direction <= 0.0:
        qr, vr = ws.q_new, ws.v_new           # a value equal to the step end: the end state
        W = ws.w_new[0]
        if t_eval[j] != t_new:
            if not built:
                status = method.dense(kern, q, v, t, h, p, ws)
                counters[3] += method.DENSE_EVALS
                if status != OK:
                    _stop(out_last, counters, t, q, v, ws.w[0], since, err, extra, h)
                    return status, rows, j, since
                built = True
            method.interpolate(ws, t_eval[j], ws.q_int, ws.v_int)
            qr, vr = ws.q_int, ws.v_int
            W = _work_at(method, kern, ws, t_eval[j])
        if not _save_row(kern, rows, t_eval[j], qr, vr, W, p, since, err, out_t, out_q, out_v,
                         out_stats, extra, out_extra):
            _stop(out_last, counters, t_eval[j], qr, vr, W, since, err, extra, h)
            return NON_FINITE, rows, j, since
        rows += 1
        since = 0.0
        j += 1
    return OK, rows, j, since


@njit(inline="always")
def _terminal(method, kern, ws, ew, q, v, t, h, err, p, t_eval, j, rows, since, extra, out_t,
              out_q, out_v, out_stats, out_extra, out_last, counters):
    """A terminal event at ew.stop[0] inside the accepted step from t (dense output built): the
    rows up to the event (every-step mode: the event state; t_eval: the values before it, from
    the dense output), then the call ends there (out_last = the event state). Returns
    (status, rows)."""
    t_stop = ew.stop[0]
    W_stop = _work_at(method, kern, ws, t_stop)
    direction = 1.0 if h > 0.0 else -1.0
    if t_eval.shape[0] == 0:
        if not _save_row(kern, rows, t_stop, ew.q, ew.v, W_stop, p, since, err, out_t, out_q,
                         out_v, out_stats, extra, out_extra):
            _stop(out_last, counters, t_stop, ew.q, ew.v, W_stop, since, err, extra, h)
            return NON_FINITE, rows
        rows += 1
        since = 0.0
    while j < t_eval.shape[0] and (t_eval[j] - t_stop) * direction <= 0.0:
        method.interpolate(ws, t_eval[j], ws.q_int, ws.v_int)
        W = _work_at(method, kern, ws, t_eval[j])
        if not _save_row(kern, rows, t_eval[j], ws.q_int, ws.v_int, W, p, since, err, out_t,
                         out_q, out_v, out_stats, extra, out_extra):
            _stop(out_last, counters, t_eval[j], ws.q_int, ws.v_int, W, since, err, extra, h)
            return NON_FINITE, rows
        rows += 1
        since = 0.0
        j += 1
    _stop(out_last, counters, t_stop, ew.q, ew.v, W_stop, since, err, extra, h)
    return OK, rows


@njit(inline="always")
def run_adaptive(method, kern, n_saved, n_event_fns, q0, v0, t0, t_end, p, settings, t_eval,
                 out_t, out_q, out_v, out_stats, out_extra, out_last, out_events, counters):
    """Integrate from (q0, v0) at t0 to t_end with error control; see the module docstring.
    n_event_fns: the model's number of event functions, a literal of the glue (0: the event
    branches are pruned before compiling)."""
    n = q0.shape[0]
    size = out_t.shape[0]
    if n != kern.N_COORDS or v0.shape[0] != n:      # (the steps loop to N_COORDS: options.py)
        raise ValueError("run_<method>: q0 and v0 need N_COORDS entries (the model's "
                         "coordinates)")
    if (out_extra.shape[1] != n_saved
            or out_last.shape[0] - layout.work_at(n, n_saved) not in (0, 1) or size < 2):
        raise ValueError("run_<method>: out_extra needs n_saved columns, out_last 2 n + 3 + "
                         "n_saved entries (one more for W) and the outputs at least 2 rows")
    q = q0.copy()
    v = v0.copy()
    ws = method.workspace(kern, n)
    extra = np.zeros(n_saved)
    for k in range(n_saved):
        extra[k] = out_extra[0, k]
    # W, the work since t0, continues from row 0 of out_stats (a run in chunks)
    ws.w[0] = out_stats[0, STAT_WORK] if kern.WORK else 0.0
    status = check_state(q, v, settings.blowup_bound)
    if status == OK:
        status = method.prepare(kern, q, v, t0, p, settings, ws)
        counters[3] += 1
    if status == OK:             # a switching right-hand side classifies the start state
        status = method.apply_switch(kern, ws, q, v, t0, p, settings, extra)
    write_last(out_last, t0, q, v, 0.0, 0.0, extra)
    write_work(out_last, n, n_saved, ws.w[0])
    if status != OK:
        return status, 0, 0
    if not _save_row(kern, 0, t0, q, v, ws.w[0], p, 0.0, 0.0, out_t, out_q, out_v, out_stats,
                     extra, out_extra):
        return NON_FINITE, 0, 0
    status, h = _first_step(method, kern, q, v, t0, t_end, p, settings, ws, counters)
    if status != OK:
        return status, 1, 0
    direction = 1.0 if t_end >= t0 else -1.0
    j = points_in(t_eval, 0, t0, direction, t_eval.shape[0])     # skip values <= t0
    t, rows, since, err_last = t0, 1, 0.0, 0.0
    n_events = 0
    if n_event_fns > 0:          # (ew exists only on a model with events)
        ew = events.workspace(kern, n)
        events.start(kern, ew, q, v, t0, p)
    attempts, rejected, nonfinite_retry = 0, False, False
    while t != t_end:
        if attempts >= settings.max_steps or 0.1 * abs(h) <= abs(t) * UROUND:
            _stop(out_last, counters, t, q, v, ws.w[0], since, err_last, extra, h)
            if attempts >= settings.max_steps:
                return TOO_MANY_STEPS, rows, n_events
            return (NON_FINITE if nonfinite_retry else STEP_TOO_SMALL), rows, n_events
        last = (t + 1.01 * h - t_end) * direction > 0.0
        if last:
            h = t_end - t
        if not rejected:          # first attempt of a step: does its output fit?
            fits, h_room = _room(t_eval, j, t, h, rows, size, method.ROWS_PER_STEP)
            if not fits:
                _stop(out_last, counters, t, q, v, ws.w[0], since, err_last, extra, h)
                return OK, rows, n_events
            last = last and h_room == h
            h = h_room
        status, err = method.attempt(kern, q, v, t, h, p, settings, ws)
        attempts += 1
        counters[3] += method.STAGE_EVALS
        if status != OK:
            _stop(out_last, counters, t, q, v, ws.w[0], since, err_last, extra, h)
            return status, rows, n_events
        if not err <= 1.0:
            counters[2] += 1
            nonfinite_retry = not math.isfinite(err)
            h = retry_step(h, err, method.ERROR_EXPONENT)
            rejected = True
            continue
        t_new = t_end if last else t + h
        status = method.accept(kern, t_new, p, ws)
        counters[3] += method.ACCEPT_EVALS
        if status == OK:
            status = check_state(ws.q_new, ws.v_new, settings.blowup_bound)
        if status != OK:
            _stop(out_last, counters, t_new, ws.q_new, ws.v_new, ws.w_new[0], since, err,
                  extra, h)
            return status, rows, n_events
        counters[1] += 1
        since += 1.0
        err_last = err
        # A switching right-hand side (dop853_impacts) may end the step early, at t_new, with
        # the state there in ws.q_new, ws.v_new and the dense output of the whole step built.
        status, switched, t_new = method.switch_point(kern, ws, q, v, t, h, t_new, p, extra,
                                                      counters)
        if status != OK:
            _stop(out_last, counters, t, q, v, ws.w[0], since, err, extra, h)
            return status, rows, n_events
        if n_event_fns > 0:
            if events.crossed(kern, ew, ws.q_new, ws.v_new, t_new, p):
                if not switched:
                    status = method.dense(kern, q, v, t, h, p, ws)
                    counters[3] += method.DENSE_EVALS
                if status != OK:
                    _stop(out_last, counters, t, q, v, ws.w[0], since, err, extra, h)
                    return status, rows, n_events
                n_events, stopped = events.locate(method, ws, kern, ew, p, t, t_new,
                                                  out_events, n_events)
                if stopped:
                    status, rows = _terminal(method, kern, ws, ew, q, v, t, h, err, p, t_eval,
                                             j, rows, since, extra, out_t, out_q, out_v,
                                             out_stats, out_extra, out_last, counters)
                    return status, rows, n_events
            events.advance(ew)
        status, rows, j, since = _output(method, kern, ws, q, v, t, h, t_new, err, p, t_eval, j,
                                         rows, since, extra, out_t, out_q, out_v, out_stats,
                                         out_extra, out_last, counters, switched)
        if status != OK:
            return status, rows, n_events
        h = next_step(h, err, method.ERROR_EXPONENT, settings.h_max, rejected)
        rejected = False
        method.advance(q, v, ws)
        t = t_new
        if switched:             # the state after the switch (impulses) continues the run
            status = method.apply_switch(kern, ws, q, v, t, p, settings, extra)
            counters[3] += 1
            if status != OK:
                _stop(out_last, counters, t, q, v, ws.w[0], since, err, extra, h)
                return status, rows, n_events
            if t_eval.shape[0] == 0 and rows < size:
                if not _save_row(kern, rows, t, q, v, ws.w[0], p, since, err, out_t, out_q,
                                 out_v, out_stats, extra, out_extra):
                    _stop(out_last, counters, t, q, v, ws.w[0], since, err, extra, h)
                    return NON_FINITE, rows, n_events
                rows += 1
                since = 0.0
    _stop(out_last, counters, t, q, v, ws.w[0], since, err_last, extra, h)
    return OK, rows, n_events
