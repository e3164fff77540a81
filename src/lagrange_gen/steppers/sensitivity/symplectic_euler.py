"""Tangent of symplectic Euler (steppers/methods/symplectic_euler.py). Newton path, at the kick's
solution u (workspace): du from the kick (core.kick_tangent, hk = h), S_q+ = S_q + h du,
S_m+ = d(H(q) u + b) = D(q; u) S_q + H du + d(H u)/dp E + d b, S_v+ from v+ = H(q+)^-1 (p+ - b). Explicit path
(constant H, velocity-free forces: v+ = v + h a(q, t), q+ = q + h v+):
S_v+ = S_v + h da, S_q+ = S_q + h S_v+."""

import sys

from ...jit.cache import njit
from ..methods import symplectic_euler as _method
from ..core.options import FAST
from ..core.status import OK
from .core import (acceleration_tangent, add_parameter_columns, kick_tangent, matmul_add,
                   momentum_tangent, sensitivity_loop, set_zero, transport_tangent, velocity_tangent)
from ..core.options import explicit_path


@njit(**FAST)
def prepare(kern, q, v, t, p, settings, ws, tw, cols):
    """Newton path: S_m = d(H(q) v) at t0."""
    n = kern.N_COORDS
    if not explicit_path(kern, settings):
        momentum_tangent(kern, q, v, t, p, cols, tw.S[:n], tw.S[n:], tw.Sm, tw)
    return OK


@njit(**FAST)
def step(kern, q0, v0, q, v, t, h, p, settings, ws, tw, cols):
    n = kern.N_COORDS
    S, Sm, du = tw.S, tw.Sm, tw.T1
    Sq = S[:n]
    c = S.shape[1]
    if explicit_path(kern, settings):
        status = acceleration_tangent(kern, q0, v0, t, p, cols, Sq, S[n:], du, tw)
        if status != OK:
            return status
        for i in range(n):
            for j in range(c):
                S[n + i, j] += h * du[i, j]
                S[i, j] += h * S[n + i, j]
        return OK
    u = ws.u
    status = kick_tangent(kern, q0, u, t, h, p, cols, Sq, Sm, du, tw)
    if status != OK:
        return status
    set_zero(Sm)                                   # p+ = H(q) u + b(q)
    matmul_add(tw.D, Sq, Sm, 1.0, n)
    matmul_add(tw.H, du, Sm, 1.0, n)
    if cols.shape[0]:
        add_parameter_columns(tw.Jp2, cols, Sm, 1.0, n)
    transport_tangent(kern, q0, t, p, cols, Sq, Sm, 1.0, tw)
    for i in range(n):
        for j in range(c):
            S[i, j] += h * du[i, j]
    return velocity_tangent(kern, q, v, t + h, p, cols, Sq, Sm, S[n:], tw)


@njit(cache=True, error_model="numpy")
def run(kern, q0, v0, t0, h, n_steps, save_every, p, settings, cols, S0, out_q, out_v, out_S,
        out_stats):
    """symplectic_euler with its forward sensitivities (core.sensitivity_loop); kern: the portable
    kernel table (jit.portable.sensitivity_table)."""
    return sensitivity_loop(_method, _THIS, kern, q0, v0, t0, h, n_steps, save_every, p,
                            settings, cols, S0, out_q, out_v, out_S, out_stats)


# This module as a value for sensitivity_loop (modules, not dispatchers, are passed).
_THIS = sys.modules[__name__]
