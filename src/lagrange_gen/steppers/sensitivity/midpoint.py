"""Tangent of the midpoint variational integrator (steppers/methods/midpoint.py), by the implicit
function theorem at its Newton solution vb (workspace), qb = q + h/2 vb, tm = t + h/2 (a T1 =
b . v term adds d b(qb) as R does, core.transport_tangent):
    A dvb = S_m - (D_b - h/2 f_q) S_q - (d(H vb)/dp - h/2 f_p) E,
    A = H(qb) + h/2 D_b - h^2/4 f_q - h/2 f_v  (D_b = d(H vb)/dq; all at qb, vb, tm),
    S_q+ = S_q + h dvb,  S_m+ = S_m + h (f_q (S_q + h/2 dvb) + f_v dvb + f_p E),
and S_v+ from v+ = H(q+)^-1 p+ (core.velocity_tangent). S_m, the tangent of the carried
momentum p = H v, starts as d(H(q0) v0) (core.momentum_tangent)."""

import sys

from ...jit.cache import njit
from ..methods import midpoint as _method
from ..core.options import FAST
from ..core.status import OK, SINGULAR_NEWTON
from .core import (add_parameter_columns, factor, matmul_add, momentum_tangent,
                   momentum_tangent_rhs, sensitivity_loop, solve_columns, velocity_tangent)


@njit(**FAST)
def prepare(kern, q, v, t, p, settings, ws, tw, cols):
    """S_m = d(H(q) v) at t0."""
    n = kern.N_COORDS
    momentum_tangent(kern, q, v, t, p, cols, tw.S[:n], tw.S[n:], tw.Sm, tw)
    return OK


@njit(**FAST)
def step(kern, q0, v0, q, v, t, h, p, settings, ws, tw, cols):
    n = kern.N_COORDS
    S, Sm, dvb, dqb, A = tw.S, tw.Sm, tw.T1, tw.T2, tw.A
    Sq = S[:n]
    vb, qb, tm, hh = ws.vb, ws.qb, t + 0.5 * h, 0.5 * h
    # R gains b(qb) (momentum_tangent_rhs's transport term)
    momentum_tangent_rhs(kern, qb, vb, tm, hh, p, cols, Sq, Sm, dvb, tw)
    for i in range(n):
        for j in range(n):
            A[i, j] = tw.H[i, j] + hh * tw.D[i, j] - hh * hh * tw.Jq[i, j] - hh * tw.Jqd[i, j]
            if kern.TRANSPORT:
                A[i, j] += hh * tw.Jb[i, j]
    if not factor(A, tw.piv):
        return SINGULAR_NEWTON
    solve_columns(A, tw.piv, dvb, tw.col, tw.work, n)
    for i in range(n):
        for j in range(S.shape[1]):
            dqb[i, j] = Sq[i, j] + hh * dvb[i, j]
            Sq[i, j] += h * dvb[i, j]
    matmul_add(tw.Jq, dqb, Sm, h, n)
    matmul_add(tw.Jqd, dvb, Sm, h, n)
    if cols.shape[0]:
        add_parameter_columns(tw.Jp, cols, Sm, h, n)
    return velocity_tangent(kern, q, v, t + h, p, cols, Sq, Sm, S[n:], tw)


@njit(cache=True, error_model="numpy")
def run(kern, q0, v0, t0, h, n_steps, save_every, p, settings, cols, S0, out_q, out_v, out_S,
        out_stats):
    """midpoint with its forward sensitivities (core.sensitivity_loop); kern: the portable
    kernel table (jit.portable.sensitivity_table)."""
    return sensitivity_loop(_method, _THIS, kern, q0, v0, t0, h, n_steps, save_every, p,
                            settings, cols, S0, out_q, out_v, out_S, out_stats)


# This module as a value for sensitivity_loop (modules, not dispatchers, are passed).
_THIS = sys.modules[__name__]
