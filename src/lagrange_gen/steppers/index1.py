"""Index-1 (acceleration-level) formulation integrated by rk4: the documented bad example.

The constraint Phi(q) = 0 is replaced by its second derivative J qdd = gamma (generated
``constraints``: gamma = -(dJ/dt) v), optionally with Baumgarte's stabilization
Phi'' + 2 alpha Phi' + beta^2 Phi = 0, and the accelerations come from the KKT system

    [[H, -J^T], [J, 0]] (a, lam) = (rhs, gamma - 2 alpha J v - beta^2 Phi)

(solved through the Schur complement J H^-1 J^T, Cholesky). The resulting ODE in (q, v) is
integrated by the classical rk4 (order 4; explicit_rk's core with the rk4 tableau), which is
what a user of scipy's solve_ivp or of sympy.physics.mechanics / PyDy does.

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
from typing import NamedTuple

from numba import njit

from ..linalg import cholesky_inplace, cholesky_solve_inplace
from ..status import OK, SINGULAR_MASS
from .spec import Spec
from .base import FAST, W_ACC, run_loop
from .constrained import (S_BAUMGARTE_ALPHA, S_BAUMGARTE_BETA, check_buffers, flag_index, record,
                          schur_block, solve_rows, views)
from .explicit_rk import RK4_A, RK4_B, RK4_C, rk_step

# work rows: stage velocities 0-3, stage accelerations 4-7, stage q, new state (W_ACC = 11 kept)
_V, _A, _QS, _Q_NEW, _V_NEW = 0, 4, 8, 9, 10
_H = 0                                  # mats


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
def stage_acceleration(kern, ctx, q, v, t, a):
    """explicit_rk's callback: a (n,) from the KKT system (_accel); the stage multipliers go to
    scratch. ctx = (p, alpha, beta, H, lam, phi, J, gam, Y, S)."""
    p, alpha, beta, H, lam, phi, J, gam, Y, S = ctx
    return _accel(kern, q, v, t, p, alpha, beta, H, a, lam, phi, J, gam, Y, S)


@njit(**FAST)
def step(kern, q, v, mom, t, h, p, settings, work, mats, piv, extra):
    """One rk4 step from (q, v) at t, in place. Returns (status, 0, 0.0)."""
    n, m = q.shape[0], kern.N_CONSTRAINTS
    alpha, beta = settings[S_BAUMGARTE_ALPHA], settings[S_BAUMGARTE_BETA]
    lam, phi, gam, ls, c2, c3, J, Jb, Y, T, b, K = views(extra, n, m, m)
    S = schur_block(extra, n, m)
    H = mats[_H]
    a0, stage_v, stage_a = work[W_ACC], work[_V:_A], work[_A:_QS]
    qs, q_new, v_new = work[_QS], work[_Q_NEW], work[_V_NEW]
    flag = flag_index(m)
    if extra[flag] == 0.0:                    # first step of this run: a at the start state
        status = _accel(kern, q, v, t, p, alpha, beta, H, a0, lam, phi, J, gam, Y, S)
        if status != OK:
            return status, 0, 0.0
        extra[flag] = 1.0
    for i in range(n):
        stage_a[0, i] = a0[i]
    status = rk_step(_THIS, kern, (p, alpha, beta, H, ls, phi, J, gam, Y, S), RK4_A, RK4_B,
                     RK4_C, q, v, t, h, stage_v, stage_a, qs, q_new, v_new, True)
    if status != OK:
        return status, 0, 0.0
    # Acceleration and multiplier at the new state: reported now, first stage of the next step.
    status = _accel(kern, q_new, v_new, t + h, p, alpha, beta, H, stage_a[0], ls, phi, J, gam,
                    Y, S)
    if status != OK:
        return status, 0, 0.0
    for i in range(n):
        q[i], v[i], a0[i] = q_new[i], v_new[i], stage_a[0, i]
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

class Index1Settings(NamedTuple):
    """index1's settings: Baumgarte's (alpha, beta), Phi'' + 2 alpha Phi' + beta^2 Phi = 0."""

    blowup_bound: float = 1e150
    baumgarte: tuple = (0.0, 0.0)


SPEC = Spec(
    name="index1", order=4, family="constrained", implicit=False, symplectic=False,
    symmetric=False,
    summary="rk4 on the acceleration-level KKT form (drifts: the bad example)",
    constraints=True,
    saved=(("multipliers", "m"), ("constraint_error", 1), ("velocity_constraint_error", 1)),
    limits={"baumgarte": (0.0, True, False)},
    settings=Index1Settings,
    kernels=("constraints", "dynamics", "energy"))
