"""The layouts of the buffers a run loop shares with its driver: the one definition of each.

out_last (2n + 3 + n_saved,), or one entry longer with the work W (a fixed-step run's driver
asks for it)::

    [t, q (n), v (n), iters, resid, extra (n_saved), W]
     T  Q      v_at(n) iters_at(n) resid_at(n) extra_at(n) work_at(n, n_saved)

t, q, v: the final state, or the state a failure concerns; iters: Newton iterations (adaptive:
accepted steps) since the last saved row; resid: the largest Newton residual over them
(adaptive: the last error estimate); extra: the method's saved fields (SPEC.saved).

out_stats (S, N_STATS): one row per saved state, columns STAT_*.

out_events (E, 3 + 2n): one row per located event, ``[t, k, direction, q (n), v (n)]`` at
EV_T, EV_INDEX, EV_DIRECTION, EV_Q, ev_v_at(n) (event_width(n) columns).

The offset functions are jitted and inlined at numba-IR level (``inline="always"``) where a run
loop or the glue calls them, so an index costs what the arithmetic written out did. Python code
reads a buffer through read_last (and the sizes through last_size, event_width), which call the
same functions' Python originals (``py_func``): a stepper-library function called from Python
would first compile a twin with numba's wrappers (jit.callee).
"""

from typing import NamedTuple

import numpy as np

from ...jit.cache import njit

# out_last
T = 0               # time of the state
Q = 1               # first entry of q (n)

# Columns of out_stats (S, N_STATS), one row per saved state.
STAT_ENERGY = 0     # E = T + V at the saved state
STAT_ITERS = 1      # Newton iterations summed over the steps since the previous save
STAT_RESIDUAL = 2   # largest Newton residual (max norm, last iterate of a step) over those steps
STAT_WORK = 3       # W, the work of non-conservative forces and explicit time since t0 (work.py)
N_STATS = 4

# Columns of out_events (E, 3 + 2n), one row per located event.
EV_T = 0            # time of the event
EV_INDEX = 1        # index k of the event function (EVENT_NAMES[k])
EV_DIRECTION = 2    # +1 rising, -1 falling
EV_Q = 3            # first entry of q (n)


@njit(inline="always")
def v_at(n):
    """Index of v[0] in out_last (n coordinates)."""
    return Q + n


@njit(inline="always")
def iters_at(n):
    """Index of the iteration count in out_last."""
    return Q + 2 * n


@njit(inline="always")
def resid_at(n):
    """Index of the residual in out_last."""
    return Q + 2 * n + 1


@njit(inline="always")
def extra_at(n):
    """Index of the first saved field in out_last."""
    return Q + 2 * n + 2


@njit(inline="always")
def work_at(n, n_saved):
    """Index of W in an out_last that has it; also the length of one that has not."""
    return extra_at(n) + n_saved


@njit(inline="always")
def ev_v_at(n):
    """Column of v[0] in an out_events row."""
    return EV_Q + n


@njit(inline="always")
def event_width(n):
    """Columns of out_events."""
    return EV_Q + 2 * n


def last_size(n, n_saved, with_work=False) -> int:
    """Length of out_last for n coordinates and n_saved saved fields (plus W: with_work)."""
    # extra_at.py_func, not work_at.py_func: work_at's body calls the dispatcher extra_at,
    # which from Python compiles a twin in every new process (jit.callee).
    return extra_at.py_func(n) + n_saved + (1 if with_work else 0)


def events_size(n) -> int:
    """Columns of out_events for n coordinates (event_width, from Python)."""
    return event_width.py_func(n)


def state_slice(n) -> slice:
    """The entries of out_last holding (q, v) together (2n,)."""
    return slice(Q, v_at.py_func(n) + n)


class Last(NamedTuple):
    """out_last read by name; q, v, extra are views of the buffer."""
    t: float
    q: np.ndarray           # (n,)
    v: np.ndarray           # (n,)
    iters: float
    resid: float
    extra: np.ndarray       # (n_saved,)
    work: float             # W; NaN when the buffer has no entry for it


def read_last(last, n, with_work=False) -> Last:
    """out_last (last_size(n, n_saved, with_work),) as a Last; n_saved is what remains."""
    v0, extra0 = v_at.py_func(n), extra_at.py_func(n)
    end = last.shape[0] - 1 if with_work else last.shape[0]
    return Last(last[T], last[Q:v0], last[v0:v0 + n], last[iters_at.py_func(n)],
                last[resid_at.py_func(n)], last[extra0:end],
                last[end] if with_work else float("nan"))


def event_rows(out_events, n):
    """(t (E,), k (E,), direction (E,), q (E, n), v (E, n)) views of out_events rows."""
    v0 = ev_v_at.py_func(n)
    return (out_events[:, EV_T], out_events[:, EV_INDEX], out_events[:, EV_DIRECTION],
            out_events[:, EV_Q:v0], out_events[:, v0:v0 + n])
