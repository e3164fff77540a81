"""Tangent of explicit Euler: q+ = q + h v, v+ = v + h a(q, v, t), so
S_q+ = S_q + h S_v, S_v+ = S_v + h da with da = a_q S_q + a_v S_v + a_p E at the start."""

import sys

from ...jit.cache import njit
from ..methods import explicit_euler as _method
from ..core.options import FAST
from ..core.status import OK
from .core import acceleration_tangent, sensitivity_loop


@njit(**FAST)
def prepare(kern, q, v, t, p, settings, ws, tw, cols):
    """Nothing carried."""
    return OK


@njit(**FAST)
def step(kern, q0, v0, q, v, t, h, p, settings, ws, tw, cols):
    n = kern.N_COORDS
    S, da = tw.S, tw.T1
    status = acceleration_tangent(kern, q0, v0, t, p, cols, S[:n], S[n:], da, tw)
    if status != OK:
        return status
    for i in range(n):
        for j in range(S.shape[1]):
            S[i, j] += h * S[n + i, j]
            S[n + i, j] += h * da[i, j]
    return OK


@njit(cache=True, error_model="numpy")
def run(kern, q0, v0, t0, h, n_steps, save_every, p, settings, cols, S0, out_q, out_v, out_S,
        out_stats):
    """explicit_euler with its forward sensitivities (core.sensitivity_loop); kern: the portable
    kernel table (jit.portable.sensitivity_table)."""
    return sensitivity_loop(_method, _THIS, kern, q0, v0, t0, h, n_steps, save_every, p,
                            settings, cols, S0, out_q, out_v, out_S, out_stats)


# This module as a value for sensitivity_loop (modules, not dispatchers, are passed).
_THIS = sys.modules[__name__]
