"""The midpoint rule for nonholonomic constraints, RATTLE-type: a discrete Lagrange-d'Alembert
step whose velocity constraints hold at every step to round-off.

A model with r velocity constraints A(q, t) v + b(q, t) = 0 moves by H qdd = rhs + A^T mu
(the forces A^T mu do no work on the allowed velocities). The step is the momentum form of the
midpoint rule (as ``midpoint``: p = H v (+ b_T for a T1 term), f = dL/dq + Q_nc, the
``momentum_rate``) with the constraint impulse split between the two ends of the step, as RATTLE
splits a holonomic one (McLachlan and Perlmutter, "Integrators for nonholonomic mechanical
systems", J. Nonlinear Sci. 16, 2006, treat this family): with the unknown mean velocity
vb = (q+ - q)/h, qb = q + h/2 vb, tm = t + h/2, and nu the impulse at the start,

    R1 = H(qb) vb - h/2 f(qb, vb, tm) - p - A(q)^T nu = 0          (n)
    R2 = A(qb) vb + b(qb, tm) = 0                                    (r)  the discrete constraint
    p~ = p + A(q)^T nu + h f(qb, vb, tm),   q+ = q + h vb
    p+ = p~ + A(q+)^T eta  with  A(q+) v+ + b(q+, t + h) = 0,  v+ = H(q+)^-1 (p+ - b_T)  (linear)

R2 is the constraint on the midpoint displacement (the discrete constraint space of a discrete
Lagrange-d'Alembert principle); the end impulse eta puts the velocity of the new state on the
exact constraint A(q+) v+ + b = 0, which therefore holds to round-off at every step (not only
to the Newton tolerance). The scheme is symmetric (time-reversible on a reversible system such as
the sleigh) and of order 2. The exact flow of a conservative rolling system conserves the energy;
a nonholonomic flow is not symplectic, so no general theorem bounds a method's energy error. What
examples/rolling_energy.py measures at h = 0.05: on the Chaplygin sleigh in a harmonic well
(models/sleigh_in_well.py) the error is 4e-4 up to t = 200 and creeps to 4e-3 by t = 10000
(nonholonomic_rk4: 1e-6 growing to 7e-5, with |A v + b| reaching 9e-5); on the vertical rolling
disk it stays at round-off (7e-9 by t = 10000; rk4: 9e-8, |A v + b| 4e-8).

Newton on (vb, nu) with the exact Jacobian

    [[H(qb) + h/2 d(H vb)/dq - h^2/4 df/dq - h/2 df/dv,   -A(q)^T],
     [A(qb) + h/2 d(A vb + b)/dq (at qb),                    0    ]]

from ``mass_matvec_dq``, ``momentum_rate_jacobian`` and ``nonholonomic_dq``, through
newton.solve; it starts from vb = v and nu = h/2 mu of the previous step. The end projection is
constrained.velocity_projection with the rows A(q+) and the rate b(q+).

``extra`` (SPEC.saved), r = kern.N_NONHOLONOMIC: mu = eta / (h/2) (r), the constraint force at
the end of the step (row 0: the KKT multiplier of the initial state), and max_i |(A v + b)_i|
(1).
"""

import sys
from collections import namedtuple

import numpy as np
from ...jit.cache import njit

from ..core import newton
from ..core.constrained import max_abs_jv, velocity_projection
from ..core.legendre import momentum_from_velocity, subtract_transport
from ..core.method_spec import NewtonSettings, Spec
from ..core.options import FAST, inline_step
from ..core.status import OK
from .nonholonomic_rk4 import constrained_acceleration

#: Scratch of one run (n coordinates, r nonholonomic constraints): the Newton unknown x = (vb,
#: nu), residual F, solver scratch s (n + r), pivots, its matrix K (n + r, n + r); the midpoint
#: qb, end point q1, velocity v1, momentum rate f, momentum pt, an acceleration a (n); H, df/dq,
#: df/dv, d(H vb)/dq, d(A^T mu)/dq (unused) (n, n); A(q) A0, A(qb) Ab, A(q1) A1, d(A vb + b)/dq
#: dc, unused outputs dAw, dgq, dgqd, H^-1 A^T rows Y (r, n); b, gamma, the end impulse eta,
#: multipliers mu (r); Schur complement S (r, r).
Workspace = namedtuple("Workspace", "x F s piv K qb q1 v1 f pt a H Jq Jqd dHw dATmu A0 Ab A1 dc "
                                    "dAw dgq dgqd Y b gam eta mu S")


@njit
def workspace(kern, n):
    """Allocated once per run by run_loop.run_loop."""
    r = kern.N_NONHOLONOMIC
    N = n + r
    return Workspace(np.zeros(N), np.zeros(N), np.zeros(N), np.zeros(N, np.int64),
                     np.zeros((N, N)), np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n),
                     np.zeros(n), np.zeros(n), np.zeros((n, n)), np.zeros((n, n)),
                     np.zeros((n, n)), np.zeros((n, n)), np.zeros((n, n)), np.zeros((r, n)),
                     np.zeros((r, n)), np.zeros((r, n)), np.zeros((r, n)), np.zeros((r, n)),
                     np.zeros((r, n)), np.zeros((r, n)), np.zeros((r, n)), np.zeros(r),
                     np.zeros(r), np.zeros(r), np.zeros(r), np.zeros((r, r)))


@njit(**FAST)
def record(kern, extra, mu, A, v, b):
    """The saved fields: mu, then max|A v + b| (A, b at the state of v)."""
    r = kern.N_NONHOLONOMIC
    for k in range(r):
        extra[k] = mu[k]
    extra[r] = max_abs_jv(A, v, b)


@njit(**FAST)
def prepare(kern, q, v, mom, t, p, settings, ws, extra):
    """The momentum p = H(q) v (+ b_T), A(q) in ws.A0 (each step leaves A(q+) there for the
    next) and the saved fields of row 0 with the KKT multiplier of the initial state."""
    status = constrained_acceleration(kern, q, v, t, p, ws.H, ws.a, ws.mu, ws.A0, ws.b, ws.gam,
                                      ws.Y, ws.S)
    if status != OK:
        return status
    record(kern, extra, ws.mu, ws.A0, v, ws.b)
    momentum_from_velocity(kern, q, v, t, p, ws.H, mom)
    return OK


@njit(inline="always")
def assemble(kern, args, x, F, K):
    """Newton system of the step (newton.solve): F (n + r) <- (R1, R2) at x = (vb, nu), K its
    Jacobian."""
    q, mom, tm, h, p, qb, f, H, Jq, Jqd, dHw, A0, Ab, b, gam, dc, dAw, dATmu, dgq, dgqd, mu = args
    n, r = q.shape[0], b.shape[0]
    hh = 0.5 * h
    for i in range(n):
        qb[i] = q[i] + hh * x[i]
    vb = x[:n]
    kern.mass_matrix(qb, tm, p, H)
    kern.mass_matvec_dq(qb, vb, tm, p, dHw)
    kern.momentum_rate(qb, vb, tm, p, f)
    kern.momentum_rate_jacobian(qb, vb, tm, p, Jq, Jqd)
    kern.nonholonomic(qb, vb, tm, p, Ab, b, gam)
    kern.nonholonomic_dq(qb, vb, vb, mu, tm, p, dAw, dATmu, dc, dgq, dgqd)
    if kern.TRANSPORT:                        # p = H v + b_T: R1 gains b_T(qb), its Jacobian h/2 db_T/dq
        kern.transport_dq(qb, tm, p, dHw)
    for i in range(n):
        s = -mom[i] - hh * f[i]
        for j in range(n):
            s += H[i, j] * x[j]
            K[i, j] = H[i, j] + hh * dHw[i, j] - hh * hh * Jq[i, j] - hh * Jqd[i, j]
        for k in range(r):
            s -= A0[k, i] * x[n + k]
            K[i, n + k] = -A0[k, i]
        F[i] = s
    for k in range(r):
        s = b[k]
        for j in range(n):
            s += Ab[k, j] * x[j]
            K[n + k, j] = Ab[k, j] + hh * dc[k, j]
        for j in range(r):
            K[n + k, n + j] = 0.0
        F[n + k] = s
    if kern.TRANSPORT:
        kern.transport(qb, tm, p, F[:n])


@njit(inline=inline_step, **FAST)
def step(kern, q, v, mom, t, h, p, settings, ws, extra):
    """One step from (q, v, mom) at t, in place. Returns (status, Newton iterations, residual)."""
    n, r = q.shape[0], kern.N_NONHOLONOMIC
    x, qb, q1, f, pt, v1 = ws.x, ws.qb, ws.q1, ws.f, ws.pt, ws.v1
    hh, tm = 0.5 * h, t + 0.5 * h
    for i in range(n):
        x[i] = v[i]
    for k in range(r):
        x[n + k] = hh * extra[k]              # nu from the previous step's multiplier
    args = (q, mom, tm, h, p, qb, f, ws.H, ws.Jq, ws.Jqd, ws.dHw, ws.A0, ws.Ab, ws.b, ws.gam,
            ws.dc, ws.dAw, ws.dATmu, ws.dgq, ws.dgqd, ws.mu)
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
        for k in range(r):
            s += ws.A0[k, i] * x[n + k]
        pt[i] = s
        v1[i] = s
    t1 = t + h
    kern.nonholonomic(q1, vb, t1, p, ws.A1, ws.b, ws.gam)
    subtract_transport(kern, q1, t1, p, v1)   # v = H^-1 (p - b_T)
    status = velocity_projection(kern, q1, t1, p, ws.A1, ws.Y, ws.H, ws.S, ws.eta, v1, True, ws.b)
    if status != OK:
        return status, iters, resid
    for i in range(n):
        s = pt[i]
        for k in range(r):
            s += ws.A1[k, i] * ws.eta[k]
        q[i], v[i], mom[i] = q1[i], v1[i], s
    for k in range(r):
        ws.mu[k] = ws.eta[k] / hh
        for j in range(n):
            ws.A0[k, j] = ws.A1[k, j]
    record(kern, extra, ws.mu, ws.A1, v, ws.b)
    return OK, iters, resid


# This module as a value for newton.solve (see core/run_loop.py: modules, not dispatchers, are passed).
_THIS = sys.modules[__name__]

SPEC = Spec(
    name="nonholonomic_midpoint", order=2, family="constrained", implicit=True, symplectic=False,
    symmetric=True,
    summary="midpoint discrete Lagrange-d'Alembert, RATTLE-type (A v + b = 0 to round-off)",
    nonholonomic=True, constraint_drift="none",
    saved=(("multipliers", "r"), ("velocity_constraint_error", 1)),
    settings=NewtonSettings,
    kernels=("dynamics", "mass_matrix", "mass_matvec_dq", "momentum_rate",
             "momentum_rate_jacobian", "nonholonomic", "nonholonomic_dq", "transport",
             "transport_dq"))
