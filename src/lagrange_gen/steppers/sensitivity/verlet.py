"""Tangent of Stormer-Verlet (steppers/methods/verlet.py). Newton path, at the step's Newton
solutions u, w (workspace): the kick's du (core.kick_tangent, hk = h/2), S_* = d(H(q) u); the
drift H(q+) w = p*, q+ = q + h/2 (u + w):
    (H(q+) + h/2 D(q+; w)) dw = S_* - D(q+; w) (S_q + h/2 du) - d(H w)/dp E,
S_q+ = S_q + h/2 (du + dw), S_m+ = S_* + h/2 (f_q S_q+ + f_v dw + f_p E) at (q+, w, t + h)
(a T1 = b . v term adds its d b where H u and H w appear, core.transport_tangent), and
S_v+ from v+ = H(q+)^-1 p+. Explicit path (velocity Verlet with the acceleration cached between
steps): S_m holds the cached acceleration's tangent, dv* = S_v + h/2 S_a, S_q+ = S_q + h dv*,
S_a+ = da at (q+, v*, t + h), S_v+ = dv* + h/2 S_a+."""

import sys

from ...jit.cache import njit
from ..methods import verlet as _method
from ..core.options import FAST
from ..core.status import OK, SINGULAR_NEWTON
from .core import (acceleration_tangent, add_parameter_columns, copy_matrix, factor, kick_tangent,
                   matmul_add, momentum_tangent, sensitivity_loop, set_zero, solve_columns,
                   transport_tangent, velocity_tangent)
from ..core.options import explicit_path


@njit(**FAST)
def prepare(kern, q, v, t, p, settings, ws, tw, cols):
    """Newton path: S_m = d(H(q) v); explicit path: S_m = da at t0 (the cached acceleration)."""
    n = kern.N_COORDS
    if explicit_path(kern, settings):
        return acceleration_tangent(kern, q, v, t, p, cols, tw.S[:n], tw.S[n:], tw.Sm, tw)
    momentum_tangent(kern, q, v, t, p, cols, tw.S[:n], tw.S[n:], tw.Sm, tw)
    return OK


@njit(**FAST)
def step(kern, q0, v0, q, v, t, h, p, settings, ws, tw, cols):
    n = kern.N_COORDS
    S, Sm, du, dw = tw.S, tw.Sm, tw.T1, tw.T2
    Sq, Sv = S[:n], S[n:]
    c = S.shape[1]
    hh, t1 = 0.5 * h, t + h
    if explicit_path(kern, settings):
        for i in range(n):
            for j in range(c):
                du[i, j] = Sv[i, j] + hh * Sm[i, j]          # dv*
                Sq[i, j] += h * du[i, j]
        status = acceleration_tangent(kern, q, ws.u, t1, p, cols, Sq, du, Sm, tw)
        if status != OK:
            return status
        for i in range(n):
            for j in range(c):
                Sv[i, j] = du[i, j] + hh * Sm[i, j]
        return OK
    status = kick_tangent(kern, q0, ws.u, t, hh, p, cols, Sq, Sm, du, tw)
    if status != OK:
        return status
    set_zero(Sm)                                   # S_* = d(H(q) u + b(q))
    matmul_add(tw.D, Sq, Sm, 1.0, n)
    matmul_add(tw.H, du, Sm, 1.0, n)
    if cols.shape[0]:
        add_parameter_columns(tw.Jp2, cols, Sm, 1.0, n)
    transport_tangent(kern, q0, t, p, cols, Sq, Sm, 1.0, tw)
    w, A, dq = ws.w, tw.A, tw.T3
    kern.mass_matrix(q, t1, p, tw.H)
    kern.mass_matvec_dq(q, w, t1, p, tw.D)
    for i in range(n):
        for j in range(c):
            dq[i, j] = Sq[i, j] + hh * du[i, j]
    copy_matrix(dw, Sm)
    matmul_add(tw.D, dq, dw, -1.0, n)
    if cols.shape[0]:
        kern.mass_matvec_dp(q, w, t1, p, tw.Jp2)
        add_parameter_columns(tw.Jp2, cols, dw, -1.0, n)
    transport_tangent(kern, q, t1, p, cols, dq, dw, -1.0, tw)       # the drift's b(q+)
    for i in range(n):
        for j in range(n):
            A[i, j] = tw.H[i, j] + hh * tw.D[i, j]
            if kern.TRANSPORT:
                A[i, j] += hh * tw.Jb[i, j]
    if not factor(A, tw.piv):
        return SINGULAR_NEWTON
    solve_columns(A, tw.piv, dw, tw.col, tw.work, n)
    for i in range(n):
        for j in range(c):
            Sq[i, j] += hh * (du[i, j] + dw[i, j])
    kern.momentum_rate_jacobian(q, w, t1, p, tw.Jq, tw.Jqd)
    matmul_add(tw.Jq, Sq, Sm, hh, n)
    matmul_add(tw.Jqd, dw, Sm, hh, n)
    if cols.shape[0]:
        kern.momentum_rate_dp(q, w, t1, p, tw.Jp)
        add_parameter_columns(tw.Jp, cols, Sm, hh, n)
    return velocity_tangent(kern, q, v, t1, p, cols, Sq, Sm, Sv, tw)


@njit(cache=True, error_model="numpy")
def run(kern, q0, v0, t0, h, n_steps, save_every, p, settings, cols, S0, out_q, out_v, out_S,
        out_stats):
    """verlet with its forward sensitivities (core.sensitivity_loop); kern: the portable
    kernel table (jit.portable.sensitivity_table)."""
    return sensitivity_loop(_method, _THIS, kern, q0, v0, t0, h, n_steps, save_every, p,
                            settings, cols, S0, out_q, out_v, out_S, out_stats)


# This module as a value for sensitivity_loop (modules, not dispatchers, are passed).
_THIS = sys.modules[__name__]
