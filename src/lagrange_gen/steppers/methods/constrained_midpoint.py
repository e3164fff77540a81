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
``mass_matvec_dq``, ``momentum_rate_jacobian`` and ``constraints``, through newton.solve (LU
with partial pivoting, its stopping rule on the increment). It starts from vb = v and the
previous step's multiplier.
"""

import sys
from collections import namedtuple

import numpy as np
from ...jit.cache import njit

from ..core import newton
from ..core.legendre import momentum_from_velocity
from ..core.options import FAST, inline_step
from ..core.constrained import SAVED, finish_momentum_step
from ..core.method_spec import NewtonSettings, Spec
from ..core.status import OK

#: Scratch of one run (n coordinates, m constraints): the Newton unknown x = (vb, nu), residual
#: F, solver scratch s (n + m), pivots, its matrix K (n + m, n + m); the midpoint qb, end point
#: q1, velocity v1, momentum rate f, momentum pt (n); H, df/dq, df/dv, d(H vb)/dq (n, n);
#: Phi, gamma, the end impulse eta (m); J(q), J(q1), H^-1 J^T rows Y (m, n); Schur S (m, m).
Workspace = namedtuple("Workspace", "x F s piv K qb q1 v1 f pt H Jq Jqd dHw phi gam eta Ja Jb "
                                    "Y S")


@njit
def workspace(kern, n):
    """Allocated once per run by run_loop.run_loop."""
    m = kern.N_CONSTRAINTS
    N = n + m
    return Workspace(np.zeros(N), np.zeros(N), np.zeros(N), np.zeros(N, np.int64),
                     np.zeros((N, N)), np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n),
                     np.zeros(n), np.zeros((n, n)), np.zeros((n, n)), np.zeros((n, n)),
                     np.zeros((n, n)), np.zeros(m), np.zeros(m), np.zeros(m), np.zeros((m, n)),
                     np.zeros((m, n)), np.zeros((m, n)), np.zeros((m, m)))


@njit(**FAST)
def prepare(kern, q, v, mom, t, p, settings, ws, extra):
    """Carry the momentum p = H(q) v between steps, and J(q) in ws.Ja (each step leaves
    J(q+) there for the next)."""
    momentum_from_velocity(kern, q, v, t, p, ws.H, mom)
    kern.constraints(q, v, t, p, ws.phi, ws.Ja, ws.gam)
    return OK


@njit(inline="always")
def assemble(kern, args, x, F, K):
    """Newton system of the step (newton.solve): F (n + m) <- (R1, R2) at x = (vb, nu), K its
    Jacobian."""
    q, mom, tm, h, p, qb, q1, f, H, Jq, Jqd, dHw, phi, Ja, Jb, gam = args
    n, m = q.shape[0], phi.shape[0]
    hh = 0.5 * h
    for i in range(n):
        qb[i] = q[i] + hh * x[i]
        q1[i] = q[i] + h * x[i]
    kern.mass_matrix(qb, tm, p, H)
    kern.mass_matvec_dq(qb, x[:n], tm, p, dHw)
    kern.momentum_rate(qb, x[:n], tm, p, f)
    kern.momentum_rate_jacobian(qb, x[:n], tm, p, Jq, Jqd)
    kern.constraints(q1, x[:n], tm + hh, p, phi, Jb, gam)
    if kern.TRANSPORT:                        # p = H v + b: R1 gains b(qb), its Jacobian h/2 db/dq
        kern.transport_dq(qb, tm, p, dHw)
    for i in range(n):
        r = -mom[i] - hh * f[i]
        for j in range(n):
            r += H[i, j] * x[j]
            K[i, j] = H[i, j] + hh * dHw[i, j] - hh * hh * Jq[i, j] - hh * Jqd[i, j]
        for k in range(m):
            r -= Ja[k, i] * x[n + k]
            K[i, n + k] = -Ja[k, i]
        F[i] = r
    for k in range(m):
        F[n + k] = phi[k] / h
        for j in range(n):
            K[n + k, j] = Jb[k, j]
        for j in range(m):
            K[n + k, n + j] = 0.0
    if kern.TRANSPORT:
        kern.transport(qb, tm, p, F[:n])


@njit(inline=inline_step, **FAST)
def step(kern, q, v, mom, t, h, p, settings, ws, extra):
    """One step from (q, v, mom) at t, in place. Returns (status, Newton iterations, residual)."""
    n, m = q.shape[0], kern.N_CONSTRAINTS
    x, qb, q1, f, pt = ws.x, ws.qb, ws.q1, ws.f, ws.pt
    hh, tm = 0.5 * h, t + 0.5 * h
    for i in range(n):
        x[i] = v[i]
    for k in range(m):
        x[n + k] = hh * extra[k]              # nu from the previous step's multiplier
    args = (q, mom, tm, h, p, qb, q1, f, ws.H, ws.Jq, ws.Jqd, ws.dHw, ws.phi, ws.Ja, ws.Jb,
            ws.gam)
    status, iters, resid = newton.solve(_THIS, kern, args, x, ws.F, ws.K, ws.piv, ws.s,
                                        settings.newton_tol, settings.max_iter, x.shape[0])
    if status != OK:
        return status, iters, resid
    vb = x[:n]
    for i in range(n):
        qb[i] = q[i] + hh * vb[i]
        q1[i] = q[i] + h * vb[i]
    kern.momentum_rate(qb, vb, tm, p, f)      # at the converged vb: p~ exactly
    for i in range(n):
        s = mom[i] + h * f[i]
        for k in range(m):
            s += ws.Ja[k, i] * x[n + k]
        pt[i] = s
    status = finish_momentum_step(kern, q, v, mom, q1, t + h, pt, p, hh, vb, ws.phi, ws.Jb, ws.gam,
                                  ws.Y, ws.H, ws.S, ws.eta, ws.v1, extra, ws.Ja)
    return status, iters, resid


# This module as a value for newton.solve (see core/run_loop.py: modules, not dispatchers, are passed).
_THIS = sys.modules[__name__]

SPEC = Spec(
    name="constrained_midpoint", order=2, family="constrained", implicit=True, symplectic=True,
    symmetric=True,
    summary="midpoint variational integrator with constraints",
    constraints=True,
    saved=SAVED, constraint_drift="none",
    settings=NewtonSettings,
    kernels=("constraint_rate", "constraints", "mass_matrix", "mass_matvec_dq", "momentum_rate",
             "momentum_rate_jacobian", "transport", "transport_dq"))
