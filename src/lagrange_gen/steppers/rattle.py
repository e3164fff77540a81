"""RATTLE: Stormer-Verlet with holonomic constraints, Newton on the multipliers.

Equations: H(q) qdd = rhs + J^T lam, Phi(q) = 0. In (q, p), p = H(q) v, f = dT/dq - dV/dq + Q
(generated ``momentum_rate``), one step is (Hairer-Lubich-Wanner, GNI, sec. VII.1.4):

    H(q) u = p + h/2 f(q, u, t) + h/2 J(q)^T lam          kick with the constraint force
    H(q+) w = H(q) u,    q+ = q + h/2 (u + w)              drift
    Phi(q+) = 0                                           m equations for lam
    p+ = H(q) u + h/2 f(q+, w, t + h) + h/2 J(q+)^T mu     kick
    J(q+) H(q+)^-1 p+ = 0                                 m linear equations for mu

Order 2, symmetric, symplectic on the constraint manifold's cotangent bundle; Phi(q_n) = 0 to
the Newton tolerance and J v_n = 0 to round-off at every step, so there is no drift. The
reported multiplier is mu (the force at t + h; first-order accurate in h, like RATTLE's two
multipliers separately, HLW VII.1.4).

Explicit path (constant H, velocity-free forces, settings[S_MODE] == 0: Cartesian models), the
classical RATTLE of Andersen (1983) with one force evaluation per step:

    v* = v + h/2 a(q),   q+ = q + h v* + h^2/2 M^-1 J(q)^T lam,   Phi(q+) = 0
    v+ = v* + h/2 a(q+) + h/2 M^-1 J(q+)^T mu,   J(q+) v+ = 0

Newton on kappa = h^2/2 lam with Jacobian J(q+) M^-1 J(q)^T (m x m), started from the previous
step's multiplier; M is factored once per run. It stops when every |Phi_i| / |J_i| is below the
Newton tolerance (relative to max(1, |q|)), checked at the accepted q+ (so the reported |Phi| is
verified, not extrapolated).

Newton path (H(q) or velocity-dependent forces): one Newton iteration on the whole position
stage (u, w, nu = h/2 lam), size 2n + m, with the exact Jacobian

    [[H(q) - h/2 df/dv(q, u),  0,                 -J(q)^T  ],
     [h/2 D - H(q),            H(q+) + h/2 D,      0       ],     D = d(H(q) w)/dq at q+
     [J(q+)/2,                 J(q+)/2,            0       ]]

for the residuals (kick, drift, Phi(q+)/h), solved by Gaussian elimination with partial
pivoting (constrained.gauss_solve). A singular Newton matrix is SINGULAR_NEWTON (NON_FINITE when
it holds NaN or inf); a singular J M^-1 J^T on the explicit path (redundant constraints) is
SINGULAR_MASS.
"""

import sys

from numba import njit

from ..linalg import cholesky_inplace, cholesky_solve_inplace
from ..status import NEWTON_DIVERGED, OK, SINGULAR_MASS
from .spec import PartitionedSettings, Spec
from .base import (FAST, increment_converged, S_MAX_ITER, S_TOL, W_ACC, explicit_path,
                   failed_solve_status, max_abs, momentum_from_velocity, run_loop)
from .constrained import (check_buffers, flag_index, gauss_solve, phi_small,
                          project, record, schur_block, solve_rows, velocity_projection, views)

_VH, _Z, _QN, _VN, _F, _U, _W, _PT = 0, 1, 2, 3, 4, 5, 6, 7     # work rows (W_ACC is kept)
_L, _H, _H1, _JQ, _JQD, _D = 0, 1, 2, 3, 4, 5                  # mats (_L kept: chol(M))


@njit(**FAST)
def prepare(kern, q, v, mom, t, p, settings, work, mats, piv):
    """Explicit path: factor the constant M once (mats[_L]) and cache a(q, t) in work[W_ACC].
    Newton path: carry p = H(q) v."""
    if explicit_path(kern, settings):
        L, acc = mats[_L], work[W_ACC]
        kern.dynamics(q, v, t, p, L, acc)
        if not cholesky_inplace(L):
            return SINGULAR_MASS
        cholesky_solve_inplace(L, acc)
        return OK
    momentum_from_velocity(kern, q, v, p, mats[_H], mom)
    return OK


@njit(**FAST)
def _step_explicit(kern, q, v, t, h, p, settings, work, mats, extra):
    n, m = q.shape[0], kern.N_CONSTRAINTS
    tol, max_iter = settings[S_TOL], int(settings[S_MAX_ITER])
    L, Hs = mats[_L], mats[_H]
    acc, vh, z, q1, v1, f = work[W_ACC], work[_VH], work[_Z], work[_QN], work[_VN], work[_F]
    lam, phi, gam, kap, c2, eta, Ja, Jb, Y, T, b, K = views(extra, n, m, m)
    hh = 0.5 * h
    for i in range(n):
        vh[i] = v[i] + hh * acc[i]
        z[i] = q[i] + h * vh[i]
    flag = flag_index(m)
    if extra[flag] == 0.0:                    # else Ja = J(q) is kept from the previous step
        kern.constraints(q, v, p, phi, Ja, gam)
        extra[flag] = 1.0
    solve_rows(L, Ja, Y)                      # rows M^-1 J(q)_k^T: q+ = z + Y^T kappa
    for k in range(m):
        kap[k] = hh * h * lam[k]
    iters = 0
    while True:
        for i in range(n):
            s = z[i]
            for k in range(m):
                s += Y[k, i] * kap[k]
            q1[i] = s
        kern.constraints(q1, vh, p, phi, Jb, gam)
        resid = max_abs(phi)
        if resid != resid:
            return NEWTON_DIVERGED, iters, resid
        if phi_small(phi, Jb, q1, tol):
            break
        if iters == max_iter:
            return NEWTON_DIVERGED, iters, resid
        iters += 1
        for i in range(m):
            b[i] = -phi[i]
            for k in range(m):
                s = 0.0
                for j in range(n):
                    s += Jb[i, j] * Y[k, j]
                K[i, k] = s
        if not gauss_solve(K, b):
            return SINGULAR_MASS, iters, resid
        for k in range(m):
            kap[k] += b[k]
    for i in range(n):                        # v_1/2 = v* + h/2 M^-1 J(q)^T lam
        s = 0.0
        for k in range(m):
            s += Y[k, i] * kap[k]
        vh[i] += s / h
    # Velocity stage: forces are velocity-free here, so a(q+) does not depend on vh.
    kern.dynamics(q1, vh, t + h, p, Hs, f)
    cholesky_solve_inplace(L, f)
    for i in range(n):
        v1[i] = vh[i] + hh * f[i]
    solve_rows(L, Jb, T)
    if not project(Jb, T, v1, K, eta):        # eta = h/2 mu
        return SINGULAR_MASS, iters, resid
    for i in range(n):
        q[i], v[i], acc[i] = q1[i], v1[i], f[i]
    for k in range(m):
        lam[k] = eta[k] / hh
        for j in range(n):
            Ja[k, j] = Jb[k, j]               # J(q) of the next step
    record(extra, m, phi, Jb, v)
    return OK, iters, resid


@njit(inline="always")
def _assemble(kern, q, mom, t, h, p, u, w, nu, q1, f, H0, H1, Jq, Jqd, D, phi, Ja, Jb, gam,
              b, K):
    """Residual b = -(kick, drift, Phi(q+)/h) and its Jacobian K (2n + m) at (u, w, nu)."""
    n, m = q.shape[0], phi.shape[0]
    hh = 0.5 * h
    for i in range(n):
        q1[i] = q[i] + hh * (u[i] + w[i])
    kern.momentum_rate(q, u, t, p, f)
    kern.momentum_rate_jacobian(q, u, t, p, Jq, Jqd)
    kern.mass_matrix(q1, p, H1)
    kern.mass_matvec_dq(q1, w, p, D)
    kern.constraints(q1, w, p, phi, Jb, gam)
    for i in range(n):
        ra = -mom[i] - hh * f[i]
        rb = 0.0
        for j in range(n):
            ra += H0[i, j] * u[j]
            rb += H1[i, j] * w[j] - H0[i, j] * u[j]
            K[i, j] = H0[i, j] - hh * Jqd[i, j]
            K[i, n + j] = 0.0
            K[n + i, j] = hh * D[i, j] - H0[i, j]
            K[n + i, n + j] = H1[i, j] + hh * D[i, j]
        for k in range(m):
            ra -= Ja[k, i] * nu[k]
            K[i, 2 * n + k] = -Ja[k, i]
            K[n + i, 2 * n + k] = 0.0
        b[i] = -ra
        b[n + i] = -rb
    for k in range(m):
        b[2 * n + k] = -phi[k] / h
        for j in range(n):
            K[2 * n + k, j] = 0.5 * Jb[k, j]
            K[2 * n + k, n + j] = 0.5 * Jb[k, j]
        for j in range(m):
            K[2 * n + k, 2 * n + j] = 0.0


@njit(**FAST)
def _step_newton(kern, q, v, mom, t, h, p, settings, work, mats, extra):
    n, m = q.shape[0], kern.N_CONSTRAINTS
    size = 2 * n + m
    tol, max_iter = settings[S_TOL], int(settings[S_MAX_ITER])
    u, w, q1, v1, f, pt = work[_U], work[_W], work[_QN], work[_VN], work[_F], work[_PT]
    H0, H1, Jq, Jqd, D = mats[_H], mats[_H1], mats[_JQ], mats[_JQD], mats[_D]
    lam, phi, gam, nu, c2, eta, Ja, Jb, Y, T, b, K = views(extra, n, m, size)
    hh = 0.5 * h
    kern.mass_matrix(q, p, H0)
    kern.constraints(q, v, p, phi, Ja, gam)
    for i in range(n):
        u[i] = v[i]
        w[i] = v[i]
    for k in range(m):
        nu[k] = hh * lam[k]
    resid = prev = 0.0
    converged = False
    iters = 0
    for it in range(1, max_iter + 1):
        iters = it
        _assemble(kern, q, mom, t, h, p, u, w, nu, q1, f, H0, H1, Jq, Jqd, D, phi, Ja, Jb, gam,
                  b, K)
        resid = max_abs(b)
        if resid != resid:
            return NEWTON_DIVERGED, it, resid
        if not gauss_solve(K, b):
            return failed_solve_status(K), it, resid
        xmax = 0.0
        for i in range(n):
            u[i] += b[i]
            w[i] += b[n + i]
            xmax = max(xmax, abs(u[i]), abs(w[i]))
        for k in range(m):
            nu[k] += b[2 * n + k]
            xmax = max(xmax, abs(nu[k]))
        d = max_abs(b)
        if increment_converged(d, xmax, prev, tol):
            converged = True
            break
        prev = d
    if not converged:
        return NEWTON_DIVERGED, iters, resid
    for i in range(n):
        q1[i] = q[i] + hh * (u[i] + w[i])
    kern.momentum_rate(q1, w, t + h, p, f)
    for i in range(n):
        s = hh * f[i]
        for j in range(n):
            s += H0[i, j] * u[j]              # H(q) u = p + h/2 f + J^T nu, exactly
        pt[i] = s
        v1[i] = s
    kern.constraints(q1, w, p, phi, Jb, gam)
    status = velocity_projection(kern, q1, p, Jb, Y, H1, schur_block(extra, n, m), eta, v1, True)
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


@njit(**FAST)
def step(kern, q, v, mom, t, h, p, settings, work, mats, piv, extra):
    """One step from (q, v, mom) at t, in place. Returns (status, Newton iterations, residual)."""
    if explicit_path(kern, settings):
        return _step_explicit(kern, q, v, t, h, p, settings, work, mats, extra)
    return _step_newton(kern, q, v, mom, t, h, p, settings, work, mats, extra)


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
    name="rattle", order=2, family="constrained", implicit=True, symplectic=True,
    symmetric=True,
    summary="constrained Verlet, Newton on the multipliers",
    constraints=True,
    saved=(("multipliers", "m"), ("constraint_error", 1), ("velocity_constraint_error", 1)),
    settings=PartitionedSettings,
    kernels=("constraints", "dynamics", "energy", "mass_matrix", "mass_matvec_dq", "momentum_rate", "momentum_rate_jacobian"))
