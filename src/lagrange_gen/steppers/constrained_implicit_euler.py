"""Implicit (backward) Euler on the index-3 constrained equations, with a velocity projection.

With rhs = Q - h - g (generated ``dynamics``), t1 = t + h, q1 = q + h v1 and the impulse
nu = h lam, one step solves by Newton

    R1 = H(q1) (v1 - v) - h rhs(q1, v1, t1) - J(q1)^T nu = 0      (n)
    R2 = Phi(q1) / h = 0                                          (m)

then projects the velocity onto the tangent space at q1 in the kinetic-energy metric,

    v+ = v1 + H(q1)^-1 J(q1)^T eta,   J(q1) v+ = 0   (linear in eta),   q+ = q1

(v1 is the secant velocity (q+ - q)/h, whose normal component is O(h)). The reported
multiplier is the total constraint impulse over h, lam = (nu + eta) / h.

Order 1, not symmetric, not symplectic; L-stable like backward Euler (stiff modes that are not
constraints are damped, rho = 1/sqrt(1 + tau^2) on x'' = -omega^2 x); Phi(q_n) = 0 to the Newton
tolerance and J v_n = 0 to round-off at every step.

Newton uses the exact Jacobian of (R1, R2):

    [[H + h d(H w)/dq|_{w = v1 - v} - h^2 d rhs/dq - h d rhs/dv - h d(J^T nu)/dq,   -J(q1)^T],
     [J(q1),                                                                          0      ]]

from ``mass_matvec_dq``, ``rhs_jacobian`` and ``constraint_dq`` (the curvature of the
constraints enters through d(J^T nu)/dq), solved by Gaussian elimination with partial pivoting.
"""

import sys

from numba import njit

from ..status import NEWTON_DIVERGED, OK
from .spec import NewtonSettings, Spec
from .base import (FAST, S_MAX_ITER, S_TOL, failed_solve_status, increment_converged, max_abs,
                   run_loop)
from .constrained import (check_buffers, gauss_solve, record, schur_block,
                          velocity_projection, views)

_V1, _Q1, _DV, _RHS = 0, 1, 2, 3     # work rows
_H, _JQ, _JQD, _DHW, _DJ = 0, 1, 2, 3, 4       # mats


@njit(**FAST)
def prepare(kern, q, v, mom, t, p, settings, work, mats, piv):
    """Nothing is carried between steps but the multiplier (in extra)."""
    return OK


@njit(inline="always")
def _assemble(kern, q, v, t1, h, p, v1, nu, q1, dv, rhs, H, Jq, Jqd, dHw, DJ, phi, Jb, gam, T,
              b, K):
    """Residual b = -(R1, R2) and its Jacobian K (n + m) at (v1, nu)."""
    n, m = q.shape[0], phi.shape[0]
    for i in range(n):
        q1[i] = q[i] + h * v1[i]
        dv[i] = v1[i] - v[i]
    kern.dynamics(q1, v1, t1, p, H, rhs)
    kern.rhs_jacobian(q1, v1, t1, p, Jq, Jqd)
    kern.mass_matvec_dq(q1, dv, p, dHw)
    kern.constraints(q1, v1, p, phi, Jb, gam)
    kern.constraint_dq(q1, v1, nu, p, T, DJ)     # T = d(J v1)/dq is not needed
    for i in range(n):
        r = -h * rhs[i]
        for j in range(n):
            r += H[i, j] * dv[j]
            K[i, j] = H[i, j] + h * dHw[i, j] - h * h * Jq[i, j] - h * Jqd[i, j] - h * DJ[i, j]
        for k in range(m):
            r -= Jb[k, i] * nu[k]
            K[i, n + k] = -Jb[k, i]
        b[i] = -r
    for k in range(m):
        b[n + k] = -phi[k] / h
        for j in range(n):
            K[n + k, j] = Jb[k, j]
        for j in range(m):
            K[n + k, n + j] = 0.0


@njit(**FAST)
def step(kern, q, v, mom, t, h, p, settings, work, mats, piv, extra):
    """One step from (q, v) at t, in place. Returns (status, Newton iterations, residual)."""
    n, m = q.shape[0], kern.N_CONSTRAINTS
    tol, max_iter = settings[S_TOL], int(settings[S_MAX_ITER])
    v1, q1, dv, rhs = work[_V1], work[_Q1], work[_DV], work[_RHS]
    H, Jq, Jqd, dHw, DJ = mats[_H], mats[_JQ], mats[_JQD], mats[_DHW], mats[_DJ]
    lam, phi, gam, nu, c2, eta, Ja, Jb, Y, T, b, K = views(extra, n, m, n + m)
    t1 = t + h
    for i in range(n):
        v1[i] = v[i]
    for k in range(m):
        nu[k] = h * lam[k]
    resid = prev = 0.0
    converged = False
    iters = 0
    for it in range(1, max_iter + 1):
        iters = it
        _assemble(kern, q, v, t1, h, p, v1, nu, q1, dv, rhs, H, Jq, Jqd, dHw, DJ, phi, Jb, gam,
                  T, b, K)
        resid = max_abs(b)
        if resid != resid:
            return NEWTON_DIVERGED, it, resid
        if not gauss_solve(K, b):
            return failed_solve_status(K), it, resid
        xmax = 0.0
        for i in range(n):
            v1[i] += b[i]
            xmax = max(xmax, abs(v1[i]))
        for k in range(m):
            nu[k] += b[n + k]
            xmax = max(xmax, abs(nu[k]))
        d = max_abs(b)
        if increment_converged(d, xmax, prev, tol):
            converged = True
            break
        prev = d
    if not converged:
        return NEWTON_DIVERGED, iters, resid
    for i in range(n):
        q1[i] = q[i] + h * v1[i]
    kern.constraints(q1, v1, p, phi, Jb, gam)
    status = velocity_projection(kern, q1, p, Jb, Y, H, schur_block(extra, n, m), eta, v1, False)
    if status != OK:
        return status, iters, resid
    for i in range(n):
        q[i], v[i] = q1[i], v1[i]
    for k in range(m):
        lam[k] = (nu[k] + eta[k]) / h
    record(extra, m, phi, Jb, v)
    return OK, iters, resid


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

SPEC = Spec(
    name="constrained_implicit_euler", order=1, family="constrained", implicit=True, symplectic=False,
    symmetric=False,
    summary="index-3 backward Euler with velocity projection",
    constraints=True,
    saved=(("multipliers", "m"), ("constraint_error", 1), ("velocity_constraint_error", 1)),
    settings=NewtonSettings,
    kernels=("constraint_dq", "constraints", "dynamics", "energy", "mass_matrix", "mass_matvec_dq", "rhs_jacobian"))
