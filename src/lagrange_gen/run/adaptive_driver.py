"""Drive an adaptive method's glue from Python (dop853): chunks of rows, t_eval, progress.

The adaptive glue (steppers/core/adaptive.py, run_adaptive) chooses its own steps and fills one row
per accepted step, or one per requested time of ``t_eval`` (from its dense output), until t_end
or until the row buffers are full; it then returns with the state reached in ``last`` and the
next step proposal in ``counters[0]``, and this driver calls it again from there. Row 0 of every
call repeats the state it starts from, so the rows of the calls after the first are appended
without their row 0.
"""

from __future__ import annotations

import time

import numpy as np

from .failures import raise_for_status
from .fixed_driver import EVENT_ROWS, ProgressBar, ready_glue, remember_glue
from ..jit.compile_notice import first_use_notice
from ..steppers.core import status as st
from ..steppers.core.layout import N_STATS, STAT_WORK, events_size, last_size, read_last

#: Rows per call into the jitted loop when every accepted step is saved (the first call has
#: FIRST_ROWS, each next one four times more, up to CHUNK_ROWS).
CHUNK_ROWS = 50_000
FIRST_ROWS = 256

# counters: [h (in: first step, 0 = automatic; out: next proposal), accepted, rejected, evaluations]
C_H, C_ACCEPTED, C_REJECTED, C_EVALS = 0, 1, 2, 3


def integrate_adaptive(task, q, v, initial, t_end, t_eval, progress):
    """Run the adaptive glue from (q, v) at task.t0 to t_end.

    initial (n_saved,): row 0 of the method's saved fields; t_eval None (save every accepted
    step) or increasing times in (t0, t_end]. Returns (out, compile seconds, integration
    seconds) with out = {t (S,), q, v (S, n), stats (S, N_STATS), extra (S, n_saved), events,
    n_events, last, counters (4,)}. Raises the exception of a failure status."""
    m, n, t0 = task.module, task.module.N_COORDS, task.t0
    n_saved = initial.shape[0]
    last = np.empty(last_size(n, n_saved, with_work=True))
    counters = np.array([task.h or 0.0, 0.0, 0.0, 0.0])
    events = np.zeros((EVENT_ROWS if getattr(m, "N_EVENTS", 0) else 0, events_size(n)))
    wanted = np.zeros(0) if t_eval is None else np.asarray(t_eval, dtype=np.float64)
    label = f"run_{task.method} for {m.NAME}"
    run, compile_time = ready_glue(task), 0.0
    if run is None:
        run, compile_time = _warm_up(task, q, v, initial, last.copy(), events[:0])
        remember_glue(task, run)
    start = time.perf_counter()
    bar = ProgressBar(1000) if progress else None
    with first_use_notice(label):     # nothing compiles past the warm-up; if it does, say so
        parts, n_events = _calls(task, run, q, v, initial, last, counters, events, wanted,
                                 t_end, t_eval, bar)
    wall = time.perf_counter() - start
    if bar:
        bar.close()
    # One call (a short run) needs no concatenation: a compact copy of its rows is the same.
    out = ({k: a.copy() for k, a in parts[0].items()} if len(parts) == 1 else
           {k: np.concatenate([part[k] for part in parts]) for k in parts[0]})
    out.update(events=events, n_events=n_events, last=last, counters=counters)
    return out, compile_time, wall


def _calls(task, run, q, v, initial, last, counters, events, wanted, t_end, t_eval, bar):
    """The calls of the adaptive glue from (q, v) at task.t0 until t_end, every requested time
    or a terminal event; returns (the rows of each call, events located)."""
    m, n, t0 = task.module, task.module.N_COORDS, task.t0
    n_saved = initial.shape[0]
    parts, n_events, t = [], 0, t0
    extra0, work0 = initial.copy(), 0.0
    while True:
        # Buffers of FIRST_ROWS rows first, four times more per call up to CHUNK_ROWS: a short
        # run does not allocate (and zero) the rows of a long one.
        rows = len(wanted) + 1 if len(wanted) else min(CHUNK_ROWS, FIRST_ROWS * 4 ** len(parts))
        rows = min(rows, CHUNK_ROWS)
        buf = dict(t=np.empty(rows), q=np.empty((rows, n)), v=np.empty((rows, n)),
                   stats=np.zeros((rows, N_STATS)), extra=np.zeros((rows, n_saved)))
        buf["extra"][0] = extra0
        buf["stats"][0, STAT_WORK] = work0           # W continues from the previous call
        found = min(n_events, events.shape[0])
        code, filled, got = run(q, v, t, t_end, task.p, task.settings, wanted, buf["t"],
                                     buf["q"], buf["v"], buf["stats"], buf["extra"], last,
                                     events[found:], counters)
        n_events += got
        if code != st.OK:
            raise_for_status(code, m, task.method, int(counters[C_ACCEPTED]) + 1, None, last,
                             task.max_iter, counters[C_H], task.p)
        keep = slice(0 if not parts else 1, filled)
        parts.append({k: a[keep] for k, a in buf.items()})
        final = read_last(last, n, with_work=True)
        q, v, t = final.q.copy(), final.v.copy(), float(final.t)
        extra0, work0 = final.extra.copy(), final.work
        if len(wanted):
            wanted = wanted[filled - 1:]
        if bar:
            bar.update(int(1000 * (t - t0) / max(t_end - t0, 1e-300)))
        # Done at t_end, when every requested time is filled, or at a terminal event.
        if t >= t_end or (t_eval is not None and not len(wanted)) or _stopped(m, events,
                                                                                n_events, t):
            break
    return parts, n_events


def _stopped(module, events, n_events, t):
    """Did a terminal event end the call at time t (the last recorded event is terminal and
    at t)?"""
    row = min(n_events, events.shape[0]) - 1
    return row >= 0 and bool(module.EVENT_TERMINAL[int(events[row, 1])]) and events[row, 0] == t


def _warm_up(task, q, v, initial, last, events):
    """Choose the glue (task.glue: specialized or portable) and compile or load it from numba's
    cache with a call that stops at t0 (the glue needs two rows at least); a call longer than a
    second prints a notice (compile_notice). Returns (glue, seconds)."""
    n = q.shape[0]
    start = time.perf_counter()
    extra = np.vstack((initial, initial))
    args = (q, v, task.t0, task.t0, task.p, task.settings, np.zeros(0), np.empty(2),
            np.empty((2, n)), np.empty((2, n)), np.empty((2, N_STATS)), extra, last, events,
            np.zeros(4))
    with first_use_notice(f"run_{task.method} for {task.module.NAME}"):
        run = task.glue(args)
        run(*args)
    return run, time.perf_counter() - start
