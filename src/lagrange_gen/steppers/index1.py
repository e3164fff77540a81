"""Index-1 (acceleration-level) formulation integrated by rk4: the documented bad example.

The constraint Phi(q) = 0 is replaced by its second derivative J qdd = gamma (generated
``constraints``: gamma = -(dJ/dt) v), optionally with Baumgarte's stabilization
Phi'' + 2 alpha Phi' + beta^2 Phi = 0, and the accelerations come from the KKT system

    [[H, -J^T], [J, 0]] (a, lam) = (rhs, gamma - 2 alpha J v - beta^2 Phi)

(solved through the Schur complement J H^-1 J^T, Cholesky). The resulting ODE in (q, v) is
integrated by the classical rk4 (order 4), which is what a user of scipy's solve_ivp or of
sympy.physics.mechanics / PyDy does.

Why it is bad (Lacoursiere's slides; Hairer-Wanner II, sec. VII.2): Phi'' = 0 holds along the
numerical solution only up to the local error, so Phi and J v are not controlled at all: the
errors in J v integrate to a drift of Phi that grows with t (linearly in J v, quadratically in
Phi for a constant error source) and nothing pulls the motion back onto the manifold. Baumgarte's
terms turn the drift into a damped oscillation around Phi = 0 for alpha, beta > 0, but bias the
dynamics and need alpha, beta tuned to h. The tests and bench show |Phi| growing over 1e5 steps
while the projected methods stay at the Newton tolerance. The multiplier and the residuals are
reported at the end of every step (the acceleration there is cached for the next step's first
stage: four KKT solves per step).

Settings: settings[S_BAUMGARTE_ALPHA], settings[S_BAUMGARTE_BETA] (default 0: no stabilization).
"""

import sys

from numba import njit

from ..linalg import cholesky_inplace, cholesky_solve_inplace
from ..status import OK, SINGULAR_MASS
from .base import FAST, W_ACC, run_loop
from .constrained import (S_BAUMGARTE_ALPHA, S_BAUMGARTE_BETA, check_buffers, flag_index, record,
                          schur_block, solve_rows, views)

_QS, _VS, _A2, _A3, _A4, _V2, _V3, _V4 = 0, 1, 2, 3, 4, 5, 6, 7    # work rows (W_ACC kept)
_H = 0                                                            # mats


@njit(**FAST)
def prepare(kern, q, v, mom, t, p, settings, work, mats, piv):
    """The first step computes the acceleration at the initial state (it needs extra)."""
    return OK


@njit(**FAST)
def _accel(kern, q, v, t, p, alpha, beta, H, a, lam, phi, J, gam, Y, S):
    """a (n,) and lam (m,) from the KKT system at (q, v, t); phi, J, gam (the constraint
    kernel's outputs at q) stay available to the caller. Status OK or SINGULAR_MASS."""
    n, m = q.shape[0], phi.shape[0]
    kern.dynamics(q, v, t, p, H, a)
    kern.constraints(q, v, p, phi, J, gam)
    if not cholesky_inplace(H):
        return SINGULAR_MASS
    cholesky_solve_inplace(H, a)              # unconstrained acceleration
    solve_rows(H, J, Y)
    for i in range(m):
        s = gam[i] - beta * beta * phi[i]
        for j in range(n):
            s -= J[i, j] * (2.0 * alpha * v[j] + a[j])
        lam[i] = s
        for k in range(m):
            s = 0.0
            for j in range(n):
                s += J[i, j] * Y[k, j]
            S[i, k] = s
    if not cholesky_inplace(S):
        return SINGULAR_MASS
    cholesky_solve_inplace(S, lam)
    for k in range(m):
        for j in range(n):
            a[j] += Y[k, j] * lam[k]
    return OK


@njit(**FAST)
def step(kern, q, v, mom, t, h, p, settings, work, mats, piv, extra):
    """One rk4 step from (q, v) at t, in place. Returns (status, 0, 0.0)."""
    n, m = q.shape[0], kern.N_CONSTRAINTS
    alpha, beta = settings[S_BAUMGARTE_ALPHA], settings[S_BAUMGARTE_BETA]
    lam, phi, gam, ls, c2, c3, J, Jb, Y, T, b, K = views(extra, n, m, m)
    S = schur_block(extra, n, m)
    H = mats[_H]
    a1, qs, vs = work[W_ACC], work[_QS], work[_VS]
    a2, a3, a4, v2, v3, v4 = work[_A2], work[_A3], work[_A4], work[_V2], work[_V3], work[_V4]
    flag = flag_index(m)
    if extra[flag] == 0.0:                    # first step of this run: a at the start state
        status = _accel(kern, q, v, t, p, alpha, beta, H, a1, lam, phi, J, gam, Y, S)
        if status != OK:
            return status, 0, 0.0
        extra[flag] = 1.0
    hh = 0.5 * h
    for i in range(n):
        qs[i] = q[i] + hh * v[i]
        v2[i] = v[i] + hh * a1[i]
    status = _accel(kern, qs, v2, t + hh, p, alpha, beta, H, a2, ls, phi, J, gam, Y, S)
    if status != OK:
        return status, 0, 0.0
    for i in range(n):
        qs[i] = q[i] + hh * v2[i]
        v3[i] = v[i] + hh * a2[i]
    status = _accel(kern, qs, v3, t + hh, p, alpha, beta, H, a3, ls, phi, J, gam, Y, S)
    if status != OK:
        return status, 0, 0.0
    for i in range(n):
        qs[i] = q[i] + h * v3[i]
        v4[i] = v[i] + h * a3[i]
    status = _accel(kern, qs, v4, t + h, p, alpha, beta, H, a4, ls, phi, J, gam, Y, S)
    if status != OK:
        return status, 0, 0.0
    for i in range(n):
        qs[i] = q[i] + h / 6.0 * (v[i] + 2.0 * v2[i] + 2.0 * v3[i] + v4[i])
        vs[i] = v[i] + h / 6.0 * (a1[i] + 2.0 * a2[i] + 2.0 * a3[i] + a4[i])
    # Acceleration and multiplier at the new state: reported now, first stage of the next step.
    status = _accel(kern, qs, vs, t + h, p, alpha, beta, H, a2, ls, phi, J, gam, Y, S)
    if status != OK:
        return status, 0, 0.0
    for i in range(n):
        q[i], v[i], a1[i] = qs[i], vs[i], a2[i]
    for k in range(m):
        lam[k] = ls[k]
    record(extra, m, phi, J, v)
    return OK, 0, 0.0


@njit(inline="always")
def run(kern, q0, v0, t0, h, n_steps, save_every, p, settings,
        out_t, out_q, out_v, out_stats, out_extra, out_last):
    """See base.run_loop and constrained.py: out_extra (S, m + 2), out_last (2n + 3 + total)
    with (m + 2, total) = constrained.extra_size(n, m), settings (N_CONSTRAINED_SETTINGS,)."""
    check_buffers(kern, q0, settings, out_extra, out_last)
    return run_loop(_THIS, kern, q0, v0, t0, h, n_steps, save_every, p, settings,
                    out_t, out_q, out_v, out_stats, out_extra, out_last)


# This module as a value for run_loop (see base.py: modules, not dispatchers, are passed).
_THIS = sys.modules[__name__]
