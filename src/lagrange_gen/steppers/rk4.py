"""The classical fourth-order Runge-Kutta method on (q, v), the accuracy reference.

    a1 = a(q, v, t)
    a2 = a(q + h/2 v,  v + h/2 a1, t + h/2)           (v2 = v + h/2 a1)
    a3 = a(q + h/2 v2, v + h/2 a2, t + h/2)           (v3 = v + h/2 a2)
    a4 = a(q + h v3,   v + h a3,   t + h)             (v4 = v + h a3)
    q+ = q + h/6 (v + 2 v2 + 2 v3 + v4),   v+ = v + h/6 (a1 + 2 a2 + 2 a3 + a4)

with a = H(q)^-1 (Q - h - g) (generated dynamics, Cholesky). Order 4, explicit (four force
evaluations), neither symmetric nor symplectic: energy drifts slowly over long runs. On
x'' = -omega^2 x the stability polynomial is 1 + z + z^2/2 + z^3/6 + z^4/24 at z = i tau,
stable for tau <= 2 sqrt(2).
"""

import sys

from numba import njit

from ..status import OK
from .base import FAST, accel, run_loop

_A1, _A2, _A3, _A4, _QS, _V2, _V3, _V4 = 0, 1, 2, 3, 4, 5, 6, 7     # work rows


@njit(**FAST)
def prepare(kern, q, v, mom, t, p, settings, work, mats, piv):
    """Nothing is carried between steps."""
    return OK


@njit(**FAST)
def step(kern, q, v, mom, t, h, p, settings, work, mats, piv, extra):
    """One step from (q, v) at t, in place. Returns (status, 0, 0.0)."""
    n = q.shape[0]
    a1, a2, a3, a4 = work[_A1], work[_A2], work[_A3], work[_A4]
    qs, v2, v3, v4 = work[_QS], work[_V2], work[_V3], work[_V4]
    H = mats[0]
    status = accel(kern, q, v, t, p, H, a1)
    if status != OK:
        return status, 0, 0.0
    for i in range(n):
        qs[i] = q[i] + 0.5 * h * v[i]
        v2[i] = v[i] + 0.5 * h * a1[i]
    status = accel(kern, qs, v2, t + 0.5 * h, p, H, a2)
    if status != OK:
        return status, 0, 0.0
    for i in range(n):
        qs[i] = q[i] + 0.5 * h * v2[i]
        v3[i] = v[i] + 0.5 * h * a2[i]
    status = accel(kern, qs, v3, t + 0.5 * h, p, H, a3)
    if status != OK:
        return status, 0, 0.0
    for i in range(n):
        qs[i] = q[i] + h * v3[i]
        v4[i] = v[i] + h * a3[i]
    status = accel(kern, qs, v4, t + h, p, H, a4)
    if status != OK:
        return status, 0, 0.0
    c = h / 6.0
    for i in range(n):
        q[i] += c * (v[i] + 2.0 * v2[i] + 2.0 * v3[i] + v4[i])
        v[i] += c * (a1[i] + 2.0 * a2[i] + 2.0 * a3[i] + a4[i])
    return OK, 0, 0.0


@njit(inline="always")
def run(kern, q0, v0, t0, h, n_steps, save_every, p, settings,
        out_t, out_q, out_v, out_stats, out_extra, out_last):
    """See base.run_loop."""
    return run_loop(_THIS, kern, q0, v0, t0, h, n_steps, save_every, p, settings,
                    out_t, out_q, out_v, out_stats, out_extra, out_last)


# This module as a value for run_loop (see base.py: modules, not dispatchers, are passed).
_THIS = sys.modules[__name__]
