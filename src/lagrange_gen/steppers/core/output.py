"""Writers of a run's outputs: a saved row (out_t, out_q, out_v, out_stats, out_extra) and the
final state (out_last), in the layouts of layout.py.

Shapes: q, v (n,); extra (n_saved,) the method's saved fields; out_t (S,), out_q, out_v (S, n),
out_stats (S, N_STATS), out_extra (S, n_saved); out_last (layout.last_size(n, n_saved), or one
more entry for W).
"""

from ...jit.cache import njit

from . import layout
from .layout import STAT_ENERGY, STAT_ITERS, STAT_RESIDUAL
from .options import FAST


@njit(cache=True, **FAST)
def save_row(row, t, q, v, energy, iters, resid, out_t, out_q, out_v, out_stats, extra,
             out_extra):
    """Row ``row`` of the outputs <- the state at t, its energy, the Newton iterations and
    residual since the previous row and the saved fields (out_stats' STAT_WORK is the caller's)."""
    out_t[row] = t
    for i in range(q.shape[0]):
        out_q[row, i] = q[i]
        out_v[row, i] = v[i]
    out_stats[row, STAT_ENERGY] = energy
    out_stats[row, STAT_ITERS] = iters
    out_stats[row, STAT_RESIDUAL] = resid
    for k in range(min(extra.shape[0], out_extra.shape[1])):
        out_extra[row, k] = extra[k]


@njit(cache=True, **FAST)
def write_last(out_last, t, q, v, iters, resid, extra):
    """out_last <- [t, q, v, iters, resid, extra] (as many saved fields as it has room for;
    W, when it has an entry for it, is write_work's)."""
    n = q.shape[0]
    out_last[layout.T] = t
    v0 = layout.v_at(n)
    for i in range(n):
        out_last[layout.Q + i] = q[i]
        out_last[v0 + i] = v[i]
    out_last[layout.iters_at(n)] = iters
    out_last[layout.resid_at(n)] = resid
    e0 = layout.extra_at(n)
    for k in range(min(extra.shape[0], out_last.shape[0] - e0)):
        out_last[e0 + k] = extra[k]


@njit(inline="always")
def write_work(out_last, n, n_saved, W):
    """out_last's W entry <- W when out_last has one (a fixed-step driver asks for it)."""
    at = layout.work_at(n, n_saved)
    if out_last.shape[0] > at:
        out_last[at] = W
