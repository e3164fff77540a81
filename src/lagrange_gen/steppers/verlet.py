"""Stormer-Verlet: velocity Verlet for constant H, the generalized leapfrog for H(q).

In (q, p) with p = H(q) v and f(q, v, t) = dT/dq - dV/dq + Q (generated ``momentum_rate``), one
step is kick(h/2), drift, kick(h/2) (Hairer-Lubich-Wanner, GNI, sec. VI.3, eq. (3.4)):

    H(q) u = p + h/2 f(q, u, t)                       implicit in u  (Newton)
    p* = H(q) u
    H(q+) w = p*,  q+ = q + h/2 (u + w)               implicit in w  (Newton)
    p+ = p* + h/2 f(q+, w, t + h),   v+ = H(q+)^-1 p+ explicit

i.e. symplectic Euler A over h/2 composed with its adjoint. Order 2, symmetric, symplectic in
(q, p) for any H(q) (to the Newton tolerance). On x'' = -omega^2 x its step matrix has
eigenvalues on the unit circle for tau = h omega < 2 (rho = 1) and a real pair with rho > 1
beyond: Verlet is stable only for tau < 2.

When H is constant and forces are velocity-free (generated MASS_IS_CONSTANT and
FORCES_VELOCITY_FREE, settings[S_MODE] == 0) both implicit parts are linear and the scheme is
exactly velocity Verlet, run explicitly with one force evaluation per step (the acceleration at
the end of a step is cached for the start of the next):

    v* = v + h/2 a(q, t),   q+ = q + h v*,   v+ = v* + h/2 a(q+, t + h)
"""

import sys

from numba import njit

from ..status import OK
from .spec import PartitionedSettings, Spec
from .base import (FAST, S_MAX_ITER, S_TOL, W_ACC, accel, explicit_path, momentum_from_velocity,
                   run_loop, velocity_from_momentum)
from .partitioned import solve_drift, solve_kick

_U, _W, _R, _F, _S, _QN, _VN, _PH = 0, 1, 2, 3, 4, 5, 6, 7    # work rows (W_ACC is kept)
_H, _A, _JQ, _JQD, _DHW = 0, 1, 2, 3, 4                       # mats


@njit(**FAST)
def prepare(kern, q, v, mom, t, p, settings, work, mats, piv):
    """Explicit path: cache a(q, t) in work[W_ACC]. Newton path: carry p = H(q) v."""
    if explicit_path(kern, settings):
        return accel(kern, q, v, t, p, mats[_H], work[W_ACC])
    momentum_from_velocity(kern, q, v, p, mats[_H], mom)
    return OK


@njit(**FAST)
def _step_explicit(kern, q, v, t, h, p, work, mats):
    n = q.shape[0]
    acc, v_half, q_new, acc_new = work[W_ACC], work[_U], work[_QN], work[_F]
    for i in range(n):
        v_half[i] = v[i] + 0.5 * h * acc[i]
        q_new[i] = q[i] + h * v_half[i]
    # Forces are velocity-free here, so a(q+) does not depend on the velocity passed.
    status = accel(kern, q_new, v_half, t + h, p, mats[_H], acc_new)
    if status != OK:
        return status
    for i in range(n):
        q[i] = q_new[i]
        v[i] = v_half[i] + 0.5 * h * acc_new[i]
        acc[i] = acc_new[i]
    return OK


@njit(**FAST)
def _step_newton(kern, q, v, mom, t, h, p, settings, work, mats, piv):
    n = q.shape[0]
    tol, max_iter = settings[S_TOL], int(settings[S_MAX_ITER])
    u, w, f, q_new, v_new, p_half = work[_U], work[_W], work[_F], work[_QN], work[_VN], work[_PH]
    for i in range(n):
        u[i] = v[i]
    status, it1, res1 = solve_kick(kern, q, mom, t, 0.5 * h, p, tol, max_iter, mats[_H],
                                   mats[_A], mats[_JQ], mats[_JQD], piv, u, work[_R], f, work[_S])
    if status != OK:
        return status, it1, res1
    H = mats[_H]
    for i in range(n):
        s = 0.0
        for j in range(n):
            s += H[i, j] * u[j]
        p_half[i] = s
        w[i] = u[i]
    status, it2, res2 = solve_drift(kern, q, u, p_half, 0.5 * h, p, tol, max_iter, mats[_H],
                                    mats[_A], mats[_DHW], piv, w, work[_R], q_new, work[_S])
    iters, resid = it1 + it2, max(res1, res2)
    if status != OK:
        return status, iters, resid
    kern.momentum_rate(q_new, w, t + h, p, f)
    for i in range(n):
        p_half[i] += 0.5 * h * f[i]            # now p+
    status = velocity_from_momentum(kern, q_new, p_half, p, mats[_A], v_new)
    if status != OK:
        return status, iters, resid
    for i in range(n):
        q[i], v[i], mom[i] = q_new[i], v_new[i], p_half[i]
    return OK, iters, resid


@njit(**FAST)
def step(kern, q, v, mom, t, h, p, settings, work, mats, piv, extra):
    """One step from (q, v, mom) at t, in place. Returns (status, Newton iterations, residual)."""
    if explicit_path(kern, settings):
        return _step_explicit(kern, q, v, t, h, p, work, mats), 0, 0.0
    return _step_newton(kern, q, v, mom, t, h, p, settings, work, mats, piv)


@njit(inline="always")
def run(kern, q0, v0, t0, h, n_steps, save_every, p, settings,
        out_t, out_q, out_v, out_stats, out_extra, out_last):
    """See base.run_loop."""
    return run_loop(_THIS, kern, q0, v0, t0, h, n_steps, save_every, p, settings,
                    out_t, out_q, out_v, out_stats, out_extra, out_last)


# This module as a value for run_loop (see base.py: modules, not dispatchers, are passed).
_THIS = sys.modules[__name__]

SPEC = Spec(
    name="verlet", order=2, family="partitioned", implicit=True, symplectic=True,
    symmetric=True,
    summary="velocity Verlet / generalized leapfrog",
    stable="stable for tau < 2",
    settings=PartitionedSettings,
    kernels=("energy", "forward_dynamics", "mass_matrix", "mass_matvec_dq", "momentum_rate", "momentum_rate_jacobian"))
