"""Tangent of rk4 (steppers/core/explicit_rk.py with RK4_A, RK4_B, RK4_C): the chain rule
through the stages, at the stage states the step evaluated (its workspace's stage_v, stage_a):
    dQ_i = S_q + h sum_j A_ij dV_j,   dV_i = S_v + h sum_j A_ij dA_j,
    dA_i = a_q dQ_i + a_v dV_i + a_p E  at (Q_i, V_i, t + c_i h),
    S_q+ = S_q + h sum_i b_i dV_i,    S_v+ = S_v + h sum_i b_i dA_i."""

import sys

from ...jit.cache import njit
from ..methods import rk4 as _method
from ..core.options import FAST
from ..core.status import OK
from .core import acceleration_tangent, sensitivity_loop
from ..core.explicit_rk import RK4_A, RK4_B, RK4_C


@njit(**FAST)
def prepare(kern, q, v, t, p, settings, ws, tw, cols):
    """Nothing carried."""
    return OK


@njit(**FAST)
def step(kern, q0, v0, q, v, t, h, p, settings, ws, tw, cols):
    n, s = kern.N_COORDS, RK4_B.shape[0]
    S, dQ, dV, dA, Qs = tw.S, tw.T1, tw.dV, tw.dA, tw.Qs
    c = S.shape[1]
    for i in range(s):
        for k in range(n):
            sq = 0.0
            for j in range(i):
                if RK4_A[i, j] != 0.0:
                    sq += RK4_A[i, j] * ws.stage_v[j, k]
            Qs[k] = q0[k] + h * sq          # as explicit_rk.stage_state
            for col in range(c):
                sdq = 0.0
                sdv = 0.0
                for j in range(i):
                    if RK4_A[i, j] != 0.0:
                        sdq += RK4_A[i, j] * dV[j, k, col]
                        sdv += RK4_A[i, j] * dA[j, k, col]
                dQ[k, col] = S[k, col] + h * sdq
                dV[i, k, col] = S[n + k, col] + h * sdv
        status = acceleration_tangent(kern, Qs, ws.stage_v[i], t + RK4_C[i] * h, p, cols, dQ,
                                      dV[i], dA[i], tw)
        if status != OK:
            return status
    for k in range(n):
        for col in range(c):
            sq = 0.0
            sv = 0.0
            for i in range(s):
                sq += RK4_B[i] * dV[i, k, col]
                sv += RK4_B[i] * dA[i, k, col]
            S[k, col] += h * sq
            S[n + k, col] += h * sv
    return OK


@njit(cache=True, error_model="numpy")
def run(kern, q0, v0, t0, h, n_steps, save_every, p, settings, cols, S0, out_q, out_v, out_S,
        out_stats):
    """rk4 with its forward sensitivities (core.sensitivity_loop); kern: the portable
    kernel table (jit.portable.sensitivity_table)."""
    return sensitivity_loop(_method, _THIS, kern, q0, v0, t0, h, n_steps, save_every, p,
                            settings, cols, S0, out_q, out_v, out_S, out_stats)


# This module as a value for sensitivity_loop (modules, not dispatchers, are passed).
_THIS = sys.modules[__name__]
