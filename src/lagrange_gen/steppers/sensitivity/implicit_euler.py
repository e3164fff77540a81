"""Tangent of implicit Euler, by the implicit function theorem on the step's equations
R(v+) = H(q+) (v+ - v) - h rhs(q+, v+, t + h) = 0, q+ = q + h v+, at the Newton solution:
    A dv+ = H S_v - (D - h rhs_q) S_q - (d(H w)/dp - h rhs_p) E,   S_q+ = S_q + h dv+,
A = H + h D - h^2 rhs_q - h rhs_v (the Newton matrix at the solution), D = d(H w)/dq,
w = v+ - v, everything at (q+, v+, t + h)."""

import sys

from ...jit.cache import njit
from ..methods import implicit_euler as _method
from ..core.options import FAST
from ..core.status import OK, SINGULAR_NEWTON
from .core import (add_parameter_columns, factor, matmul_add, set_zero, solve_columns,
                   sensitivity_loop)


@njit(**FAST)
def prepare(kern, q, v, t, p, settings, ws, tw, cols):
    """Nothing carried."""
    return OK


@njit(**FAST)
def step(kern, q0, v0, q, v, t, h, p, settings, ws, tw, cols):
    n = kern.N_COORDS
    S, w, rhs_side, A = tw.S, tw.a, tw.T1, tw.A
    t1 = t + h
    for i in range(n):
        w[i] = v[i] - v0[i]
    kern.dynamics(q, v, t1, p, tw.H, tw.rhs)
    kern.rhs_jacobian(q, v, t1, p, tw.Jq, tw.Jqd)
    kern.mass_matvec_dq(q, w, t1, p, tw.D)
    set_zero(rhs_side)
    matmul_add(tw.H, S[n:], rhs_side, 1.0, n)
    matmul_add(tw.D, S[:n], rhs_side, -1.0, n)
    matmul_add(tw.Jq, S[:n], rhs_side, h, n)
    if cols.shape[0]:
        kern.mass_matvec_dp(q, w, t1, p, tw.Jp2)
        kern.rhs_dp(q, v, t1, p, tw.Jp)
        add_parameter_columns(tw.Jp2, cols, rhs_side, -1.0, n)
        add_parameter_columns(tw.Jp, cols, rhs_side, h, n)
    for i in range(n):
        for j in range(n):
            A[i, j] = tw.H[i, j] + h * tw.D[i, j] - h * h * tw.Jq[i, j] - h * tw.Jqd[i, j]
    if not factor(A, tw.piv):
        return SINGULAR_NEWTON
    solve_columns(A, tw.piv, rhs_side, tw.col, tw.work, n)
    for i in range(n):
        for j in range(S.shape[1]):
            S[i, j] += h * rhs_side[i, j]
            S[n + i, j] = rhs_side[i, j]
    return OK


@njit(cache=True, error_model="numpy")
def run(kern, q0, v0, t0, h, n_steps, save_every, p, settings, cols, S0, out_q, out_v, out_S,
        out_stats):
    """implicit_euler with its forward sensitivities (core.sensitivity_loop); kern: the portable
    kernel table (jit.portable.sensitivity_table)."""
    return sensitivity_loop(_method, _THIS, kern, q0, v0, t0, h, n_steps, save_every, p,
                            settings, cols, S0, out_q, out_v, out_S, out_stats)


# This module as a value for sensitivity_loop (modules, not dispatchers, are passed).
_THIS = sys.modules[__name__]
