"""The midpoint variational integrator with holonomic constraints (RATTLE-type endpoints).

Discrete Lagrangian L_d(q0, q1) = h L((q0 + q1)/2, (q1 - q0)/h) as in ``midpoint``; the
constraint forces act at the two ends of the step, h/2 J(q)^T lam at the start and
h/2 J(q+)^T mu at the end (the discrete constrained Lagrange-d'Alembert principle with the
constraint imposed at the nodes). With p = H(q) v, f = dT/dq - dV/dq + Q (``momentum_rate``),
the unknown mean velocity vb = (q+ - q)/h, qb = q + h/2 vb, tm = t + h/2 and nu = h/2 lam:

    R1 = H(qb) vb - h/2 f(qb, vb, tm) - p - J(q)^T nu = 0        (n)
    R2 = Phi(q + h vb) / h = 0                                    (m)
    p~ = p + J(q)^T nu + h f(qb, vb, tm),   q+ = q + h vb
    p+ = p~ + J(q+)^T eta  with  J(q+) H(q+)^-1 p+ = 0  (eta = h/2 mu, linear),  v+ = H(q+)^-1 p+

Order 2, symmetric, symplectic on the constraint manifold's cotangent bundle (to the Newton
tolerance); A-stable like the midpoint rule (no step-size limit from stiff forces that are not
constraints); Phi(q_n) = 0 to the Newton tolerance and J v_n = 0 to round-off at every step.
The reported multiplier is mu, the force at the end of the step.

Newton on (vb, nu) uses the exact Jacobian of (R1, R2):

    [[H(qb) + h/2 d(H vb)/dq - h^2/4 df/dq - h/2 df/dv,   -J(q)^T],
     [J(q + h vb),                                          0     ]]

(J(q) is the known start of the step, so no derivative of J^T nu enters), assembled from
``mass_matvec_dq``, ``momentum_rate_jacobian`` and ``constraints``, solved by Gaussian
elimination with partial pivoting (constrained.gauss_solve). It starts from vb = v and the
previous step's multiplier and stops on the Newton increment (base.newton_converged's test).
"""

import sys

from numba import njit

from ..status import NEWTON_DIVERGED, OK
from .spec import NewtonSettings, Spec
from .base import (FAST, S_MAX_ITER, S_TOL, failed_solve_status, increment_converged, max_abs,
                   momentum_from_velocity, run_loop)
from .constrained import (check_buffers, gauss_solve, record, schur_block,
                          velocity_projection, views)

_VB, _QB, _Q1, _V1, _F, _PT = 0, 1, 2, 3, 4, 5     # work rows
_H, _JQ, _JQD, _DHW = 0, 1, 2, 3                   # mats


@njit(**FAST)
def prepare(kern, q, v, mom, t, p, settings, work, mats, piv):
    """Carry the momentum p = H(q) v between steps."""
    momentum_from_velocity(kern, q, v, p, mats[_H], mom)
    return OK


@njit(inline="always")
def _assemble(kern, q, mom, tm, h, p, vb, nu, qb, q1, f, H, Jq, Jqd, dHw, phi, Ja, Jb, gam, b, K):
    """Residual b = -(R1, R2) and its Jacobian K (n + m) at (vb, nu)."""
    n, m = q.shape[0], phi.shape[0]
    hh = 0.5 * h
    for i in range(n):
        qb[i] = q[i] + hh * vb[i]
        q1[i] = q[i] + h * vb[i]
    kern.mass_matrix(qb, p, H)
    kern.mass_matvec_dq(qb, vb, p, dHw)
    kern.momentum_rate(qb, vb, tm, p, f)
    kern.momentum_rate_jacobian(qb, vb, tm, p, Jq, Jqd)
    kern.constraints(q1, vb, p, phi, Jb, gam)
    for i in range(n):
        r = -mom[i] - hh * f[i]
        for j in range(n):
            r += H[i, j] * vb[j]
            K[i, j] = H[i, j] + hh * dHw[i, j] - hh * hh * Jq[i, j] - hh * Jqd[i, j]
        for k in range(m):
            r -= Ja[k, i] * nu[k]
            K[i, n + k] = -Ja[k, i]
        b[i] = -r
    for k in range(m):
        b[n + k] = -phi[k] / h
        for j in range(n):
            K[n + k, j] = Jb[k, j]
        for j in range(m):
            K[n + k, n + j] = 0.0


@njit(**FAST)
def step(kern, q, v, mom, t, h, p, settings, work, mats, piv, extra):
    """One step from (q, v, mom) at t, in place. Returns (status, Newton iterations, residual)."""
    n, m = q.shape[0], kern.N_CONSTRAINTS
    tol, max_iter = settings[S_TOL], int(settings[S_MAX_ITER])
    vb, qb, q1, v1, f, pt = work[_VB], work[_QB], work[_Q1], work[_V1], work[_F], work[_PT]
    H, Jq, Jqd, dHw = mats[_H], mats[_JQ], mats[_JQD], mats[_DHW]
    lam, phi, gam, nu, c2, eta, Ja, Jb, Y, T, b, K = views(extra, n, m, n + m)
    hh, tm = 0.5 * h, t + 0.5 * h
    kern.constraints(q, v, p, phi, Ja, gam)
    for i in range(n):
        vb[i] = v[i]
    for k in range(m):
        nu[k] = hh * lam[k]
    resid = prev = 0.0
    converged = False
    iters = 0
    for it in range(1, max_iter + 1):
        iters = it
        _assemble(kern, q, mom, tm, h, p, vb, nu, qb, q1, f, H, Jq, Jqd, dHw, phi, Ja, Jb, gam,
                  b, K)
        resid = max_abs(b)
        if resid != resid:
            return NEWTON_DIVERGED, it, resid
        if not gauss_solve(K, b):
            return failed_solve_status(K), it, resid
        xmax = 0.0
        for i in range(n):
            vb[i] += b[i]
            xmax = max(xmax, abs(vb[i]))
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
        qb[i] = q[i] + hh * vb[i]
        q1[i] = q[i] + h * vb[i]
    kern.momentum_rate(qb, vb, tm, p, f)      # at the converged vb: p~ exactly
    for i in range(n):
        s = mom[i] + h * f[i]
        for k in range(m):
            s += Ja[k, i] * nu[k]
        pt[i] = s
        v1[i] = s
    kern.constraints(q1, vb, p, phi, Jb, gam)
    status = velocity_projection(kern, q1, p, Jb, Y, H, schur_block(extra, n, m), eta, v1, True)
    if status != OK:
        return status, iters, resid
    for i in range(n):
        s = pt[i]
        for k in range(m):
            s += Jb[k, i] * eta[k]
        q[i], v[i], mom[i] = q1[i], v1[i], s
    for k in range(m):
        lam[k] = eta[k] / hh
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
    name="constrained_midpoint", order=2, family="constrained", implicit=True, symplectic=True,
    symmetric=True,
    summary="midpoint variational integrator with constraints",
    constraints=True,
    saved=(("multipliers", "m"), ("constraint_error", 1), ("velocity_constraint_error", 1)),
    settings=NewtonSettings,
    kernels=("constraints", "energy", "mass_matrix", "mass_matvec_dq", "momentum_rate", "momentum_rate_jacobian"))
