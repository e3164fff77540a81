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
constraints enters through d(J^T nu)/dq), through newton.solve (LU with partial pivoting, its
stopping rule on the increment), starting from v1 = v and the previous step's multiplier.
"""

import sys
from collections import namedtuple

import numpy as np
from ...jit.cache import njit

from ..core import newton
from ..core.options import FAST, inline_step
from ..core.constrained import SAVED, constraint_rate, record, velocity_projection
from ..core.method_spec import NewtonSettings, Spec
from ..core.status import OK

#: Scratch of one run (n coordinates, m constraints): the Newton unknown x = (v1, nu), residual
#: F, solver scratch s (n + m), pivots, its matrix K (n + m, n + m); the end point q1, v1 - v,
#: rhs, the projected velocity vp (n); H, d rhs/dq, d rhs/dv, d(H dv)/dq, d(J^T nu)/dq (n, n);
#: Phi, gamma, the projection impulse eta (m); J(q1), d(J v1)/dq (unused), H^-1 J^T rows Y
#: (m, n); Schur S (m, m).
Workspace = namedtuple("Workspace", "x F s piv K q1 dv rhs vp H Jq Jqd dHw DJ phi gam eta Jb T "
                                    "Y S")


@njit
def workspace(kern, n):
    """Allocated once per run by run_loop.run_loop."""
    m = kern.N_CONSTRAINTS
    N = n + m
    return Workspace(np.zeros(N), np.zeros(N), np.zeros(N), np.zeros(N, np.int64),
                     np.zeros((N, N)), np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n),
                     np.zeros((n, n)), np.zeros((n, n)), np.zeros((n, n)), np.zeros((n, n)),
                     np.zeros((n, n)), np.zeros(m), np.zeros(m), np.zeros(m), np.zeros((m, n)),
                     np.zeros((m, n)), np.zeros((m, n)), np.zeros((m, m)))


@njit(**FAST)
def prepare(kern, q, v, mom, t, p, settings, ws, extra):
    """Nothing is carried between steps but the multiplier (in extra)."""
    return OK


@njit(inline="always")
def assemble(kern, args, x, F, K):
    """Newton system of the step (newton.solve): F (n + m) <- (R1, R2) at x = (v1, nu), K its
    Jacobian."""
    q, v, t1, h, p, q1, dv, rhs, H, Jq, Jqd, dHw, DJ, phi, Jb, gam, T = args
    n, m = q.shape[0], phi.shape[0]
    v1, nu = x[:n], x[n:]
    for i in range(n):
        q1[i] = q[i] + h * v1[i]
        dv[i] = v1[i] - v[i]
    kern.dynamics(q1, v1, t1, p, H, rhs)
    kern.rhs_jacobian(q1, v1, t1, p, Jq, Jqd)
    kern.mass_matvec_dq(q1, dv, t1, p, dHw)
    kern.constraints(q1, v1, t1, p, phi, Jb, gam)
    kern.constraint_dq(q1, v1, nu, t1, p, T, DJ)     # T = d(J v1)/dq is not needed
    for i in range(n):
        r = -h * rhs[i]
        for j in range(n):
            r += H[i, j] * dv[j]
            K[i, j] = H[i, j] + h * dHw[i, j] - h * h * Jq[i, j] - h * Jqd[i, j] - h * DJ[i, j]
        for k in range(m):
            r -= Jb[k, i] * nu[k]
            K[i, n + k] = -Jb[k, i]
        F[i] = r
    for k in range(m):
        F[n + k] = phi[k] / h
        for j in range(n):
            K[n + k, j] = Jb[k, j]
        for j in range(m):
            K[n + k, n + j] = 0.0


@njit(inline=inline_step, **FAST)
def step(kern, q, v, mom, t, h, p, settings, ws, extra):
    """One step from (q, v) at t, in place. Returns (status, Newton iterations, residual)."""
    n, m = q.shape[0], kern.N_CONSTRAINTS
    x, q1, vp, phi, Jb, eta = ws.x, ws.q1, ws.vp, ws.phi, ws.Jb, ws.eta
    for i in range(n):
        x[i] = v[i]
    for k in range(m):
        x[n + k] = h * extra[k]               # nu from the previous step's multiplier
    args = (q, v, t + h, h, p, q1, ws.dv, ws.rhs, ws.H, ws.Jq, ws.Jqd, ws.dHw, ws.DJ, phi, Jb,
            ws.gam, ws.T)
    status, iters, resid = newton.solve(_THIS, kern, args, x, ws.F, ws.K, ws.piv, ws.s,
                                        settings.newton_tol, settings.max_iter, x.shape[0])
    if status != OK:
        return status, iters, resid
    for i in range(n):
        q1[i] = q[i] + h * x[i]
        vp[i] = x[i]
    kern.constraints(q1, vp, t + h, p, phi, Jb, ws.gam)
    constraint_rate(kern, q1, t + h, p, ws.gam)        # gam: dPhi/dt from here on
    status = velocity_projection(kern, q1, t + h, p, Jb, ws.Y, ws.H, ws.S, eta, vp, False, ws.gam)
    if status != OK:
        return status, iters, resid
    for i in range(n):
        q[i], v[i] = q1[i], vp[i]
    for k in range(m):
        extra[k] = (x[n + k] + eta[k]) / h    # total impulse over h
    record(extra, m, phi, Jb, v, ws.gam)
    return OK, iters, resid


# This module as a value for newton.solve (see core/run_loop.py: modules, not dispatchers, are passed).
_THIS = sys.modules[__name__]

SPEC = Spec(
    name="constrained_implicit_euler", order=1, family="constrained", implicit=True,
    symplectic=False, symmetric=False,
    summary="index-3 backward Euler with velocity projection",
    constraints=True,
    saved=SAVED, constraint_drift="none",
    settings=NewtonSettings,
    kernels=("constraint_dq", "constraint_rate", "constraints", "dynamics", "mass_matrix",
             "mass_matvec_dq", "rhs_jacobian"))
