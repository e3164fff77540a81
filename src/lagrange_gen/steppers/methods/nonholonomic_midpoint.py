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

Holonomic constraints Phi(q, t) = 0 beside the velocity ones (m of them: a bicycle's wheels
touching the ground) are treated as constrained_midpoint treats them: their rows J join A in
both impulses, C = [J; A] and nu = (nu_J, nu_A), and the position constraint at the end of the
step replaces the midpoint one, R2_J = Phi(q + h vb, t + h) / h = 0; the end projection imposes
C(q+) v+ + (dPhi/dt; b) = 0.

Newton on (vb, nu) with the exact Jacobian

    [[H(qb) + h/2 d(H vb)/dq - h^2/4 df/dq - h/2 df/dv,   -C(q)^T],
     [J(q + h vb)                                              0   ],
     [A(qb) + h/2 d(A vb + b)/dq (at qb),                      0   ]]

from ``mass_matvec_dq``, ``momentum_rate_jacobian``, ``constraints`` and ``nonholonomic_dq``,
through newton.solve; it starts from vb = v and nu = h/2 times the previous step's multipliers.
The end projection is constrained.velocity_projection with the rows C(q+).

``extra`` (SPEC.saved), m = kern.N_CONSTRAINTS, r = kern.N_NONHOLONOMIC: mu = eta_A / (h/2)
(r), the velocity constraints' force at the end of the step (row 0: the KKT multiplier of the
initial state), max_i |(C v + rate)_i| (1) over all rows, the holonomic multipliers
lam = eta_J / (h/2) (m) and max |Phi| (1).
"""

import sys
from collections import namedtuple

import numpy as np
from ...jit.cache import njit

from ..core import newton
from ..core.constrained import constraint_rate, max_abs_jv, velocity_projection
from ..core.legendre import momentum_from_velocity, subtract_transport
from ..core.method_spec import NewtonSettings, Spec
from ..core.options import FAST, inline_step
from ..core.status import OK
from .nonholonomic_rk4 import constrained_acceleration

#: Scratch of one run (n coordinates, m holonomic and r nonholonomic constraints, s = m + r):
#: the Newton unknown x = (vb, nu), residual F, solver scratch (n + s), pivots, its matrix K
#: (n + s, n + s); the midpoint qb, end point q1, velocity v1, momentum rate f, momentum pt, an
#: acceleration a (n); H, df/dq, df/dv, d(H vb)/dq, d(A^T mu)/dq (unused) (n, n); the stacked
#: rows C0 = C(q), C1 = C(q1) (s, n) and their rates rate (s); A(qb) Ab, d(A vb + b)/dq dc,
#: unused outputs dAw, dgq, dgqd (r, n); H^-1 C^T rows Y (s, n); b, gamma, multipliers mu (r);
#: Phi, J's gamma (m), J Jb (m, n); the end impulse eta (s); Schur complements S (s, s) and
#: Sr (r, r) (the initial multiplier).
Workspace = namedtuple("Workspace", "x F s piv K qb q1 v1 f pt a H Jq Jqd dHw dATmu C0 C1 rate "
                                    "Ab dc dAw dgq dgqd Y b gam mu phi gamJ Jb eta S Sr")


@njit
def workspace(kern, n):
    """Allocated once per run by run_loop.run_loop."""
    m, r = kern.N_CONSTRAINTS, kern.N_NONHOLONOMIC
    s = m + r
    N = n + s
    return Workspace(np.zeros(N), np.zeros(N), np.zeros(N), np.zeros(N, np.int64),
                     np.zeros((N, N)), np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n),
                     np.zeros(n), np.zeros(n), np.zeros((n, n)), np.zeros((n, n)),
                     np.zeros((n, n)), np.zeros((n, n)), np.zeros((n, n)), np.zeros((s, n)),
                     np.zeros((s, n)), np.zeros(s), np.zeros((r, n)), np.zeros((r, n)),
                     np.zeros((r, n)), np.zeros((r, n)), np.zeros((r, n)), np.zeros((s, n)),
                     np.zeros(r), np.zeros(r), np.zeros(r), np.zeros(m), np.zeros(m),
                     np.zeros((m, n)), np.zeros(s), np.zeros((s, s)), np.zeros((r, r)))


@njit(**FAST)
def stacked_rows(kern, q, v, t, p, ws):
    """ws.C1 <- C(q, t) = [J; A] (s, n) and ws.rate <- (dPhi/dt; b) (s,) at (q, t), ws.phi <-
    Phi; ws.b, ws.gam, ws.Jb, ws.gamJ are overwritten."""
    m, r, n = kern.N_CONSTRAINTS, kern.N_NONHOLONOMIC, q.shape[0]
    if m:
        kern.constraints(q, v, t, p, ws.phi, ws.Jb, ws.gamJ)
        constraint_rate(kern, q, t, p, ws.gamJ)
    kern.nonholonomic(q, v, t, p, ws.Ab, ws.b, ws.gam)
    for k in range(m):
        ws.rate[k] = ws.gamJ[k]
        for j in range(n):
            ws.C1[k, j] = ws.Jb[k, j]
    for k in range(r):
        ws.rate[m + k] = ws.b[k]
        for j in range(n):
            ws.C1[m + k, j] = ws.Ab[k, j]


@njit(**FAST)
def record(kern, extra, ws, v, eta, hh):
    """The saved fields: mu (r), max|C v + rate|, lam (m), max|Phi| (C, rate, Phi at the state of
    v); eta (s) the end impulses, hh = h/2 (or 1 with eta the multipliers themselves)."""
    m, r = kern.N_CONSTRAINTS, kern.N_NONHOLONOMIC
    for k in range(r):
        extra[k] = eta[m + k] / hh
    extra[r] = max_abs_jv(ws.C1, v, ws.rate)
    worst = 0.0
    for k in range(m):
        extra[r + 1 + k] = eta[k] / hh
        worst = max(worst, abs(ws.phi[k]))
    extra[r + 1 + m] = worst


@njit(**FAST)
def prepare(kern, q, v, mom, t, p, settings, ws, extra):
    """The momentum p = H(q) v (+ b_T), C(q) in ws.C0 (each step leaves C(q+) there for the
    next) and the saved fields of row 0: the velocity constraints' KKT multiplier of the initial
    state on a model without holonomic constraints, zeros with them (the first step's Newton
    then starts from zero impulses)."""
    m, r, n = kern.N_CONSTRAINTS, kern.N_NONHOLONOMIC, q.shape[0]
    for k in range(m + r):
        ws.eta[k] = 0.0
    if m == 0:
        status = constrained_acceleration(kern, q, v, t, p, ws.H, ws.a, ws.mu, ws.Ab, ws.b,
                                          ws.gam, ws.dgq, ws.Sr)
        if status != OK:
            return status
        for k in range(r):
            ws.eta[k] = ws.mu[k]
    stacked_rows(kern, q, v, t, p, ws)
    for k in range(m + r):
        for j in range(n):
            ws.C0[k, j] = ws.C1[k, j]
    record(kern, extra, ws, v, ws.eta, 1.0)
    momentum_from_velocity(kern, q, v, t, p, ws.H, mom)
    return OK


@njit(inline="always")
def assemble(kern, args, x, F, K):
    """Newton system of the step (newton.solve): F (n + s) <- (R1, R2_J, R2_A) at x = (vb, nu),
    K its Jacobian."""
    (q, mom, tm, h, p, qb, q1, f, H, Jq, Jqd, dHw, C0, Ab, b, gam, dc, dAw, dATmu, dgq, dgqd, mu,
     phi, gamJ, Jb) = args
    n, m, r = q.shape[0], phi.shape[0], b.shape[0]
    s, hh = m + r, 0.5 * h
    for i in range(n):
        qb[i] = q[i] + hh * x[i]
        q1[i] = q[i] + h * x[i]
    vb = x[:n]
    kern.mass_matrix(qb, tm, p, H)
    kern.mass_matvec_dq(qb, vb, tm, p, dHw)
    kern.momentum_rate(qb, vb, tm, p, f)
    kern.momentum_rate_jacobian(qb, vb, tm, p, Jq, Jqd)
    kern.nonholonomic(qb, vb, tm, p, Ab, b, gam)
    kern.nonholonomic_dq(qb, vb, vb, mu, tm, p, dAw, dATmu, dc, dgq, dgqd)
    if m:
        kern.constraints(q1, vb, tm + hh, p, phi, Jb, gamJ)
    if kern.TRANSPORT:                        # p = H v + b_T: R1 gains b_T(qb), its Jacobian h/2 db_T/dq
        kern.transport_dq(qb, tm, p, dHw)
    for i in range(n):
        acc = -mom[i] - hh * f[i]
        for j in range(n):
            acc += H[i, j] * x[j]
            K[i, j] = H[i, j] + hh * dHw[i, j] - hh * hh * Jq[i, j] - hh * Jqd[i, j]
        for k in range(s):
            acc -= C0[k, i] * x[n + k]
            K[i, n + k] = -C0[k, i]
        F[i] = acc
    for k in range(m):
        F[n + k] = phi[k] / h
        for j in range(n):
            K[n + k, j] = Jb[k, j]
        for j in range(s):
            K[n + k, n + j] = 0.0
    for k in range(r):
        acc = b[k]
        for j in range(n):
            acc += Ab[k, j] * x[j]
            K[n + m + k, j] = Ab[k, j] + hh * dc[k, j]
        for j in range(s):
            K[n + m + k, n + j] = 0.0
        F[n + m + k] = acc
    if kern.TRANSPORT:
        kern.transport(qb, tm, p, F[:n])


@njit(inline=inline_step, **FAST)
def step(kern, q, v, mom, t, h, p, settings, ws, extra):
    """One step from (q, v, mom) at t, in place. Returns (status, Newton iterations, residual)."""
    n, m, r = q.shape[0], kern.N_CONSTRAINTS, kern.N_NONHOLONOMIC
    s = m + r
    x, qb, q1, f, pt, v1 = ws.x, ws.qb, ws.q1, ws.f, ws.pt, ws.v1
    hh, tm = 0.5 * h, t + 0.5 * h
    for i in range(n):
        x[i] = v[i]
    for k in range(r):
        x[n + m + k] = hh * extra[k]          # nu from the previous step's multipliers
    for k in range(m):
        x[n + k] = hh * extra[r + 1 + k]
    args = (q, mom, tm, h, p, qb, q1, f, ws.H, ws.Jq, ws.Jqd, ws.dHw, ws.C0, ws.Ab, ws.b, ws.gam,
            ws.dc, ws.dAw, ws.dATmu, ws.dgq, ws.dgqd, ws.mu, ws.phi, ws.gamJ, ws.Jb)
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
        acc = mom[i] + h * f[i]
        for k in range(s):
            acc += ws.C0[k, i] * x[n + k]
        pt[i] = acc
        v1[i] = acc
    t1 = t + h
    stacked_rows(kern, q1, vb, t1, p, ws)
    subtract_transport(kern, q1, t1, p, v1)   # v = H^-1 (p - b_T)
    status = velocity_projection(kern, q1, t1, p, ws.C1, ws.Y, ws.H, ws.S, ws.eta, v1, True,
                                 ws.rate)
    if status != OK:
        return status, iters, resid
    for i in range(n):
        acc = pt[i]
        for k in range(s):
            acc += ws.C1[k, i] * ws.eta[k]
        q[i], v[i], mom[i] = q1[i], v1[i], acc
    for k in range(s):
        for j in range(n):
            ws.C0[k, j] = ws.C1[k, j]
    record(kern, extra, ws, v, ws.eta, hh)
    return OK, iters, resid


# This module as a value for newton.solve (see core/run_loop.py: modules, not dispatchers, are passed).
_THIS = sys.modules[__name__]

SPEC = Spec(
    name="nonholonomic_midpoint", order=2, family="constrained", implicit=True, symplectic=False,
    symmetric=True,
    summary="midpoint discrete Lagrange-d'Alembert, RATTLE-type (A v + b = 0 to round-off)",
    nonholonomic=True, holonomic_too=True, constraint_drift="none",
    saved=(("multipliers", "r"), ("velocity_constraint_error", 1),
           ("holonomic_multipliers", "m"), ("position_constraint_error", 1)),
    settings=NewtonSettings,
    kernels=("constraint_rate", "constraints", "dynamics", "mass_matrix", "mass_matvec_dq",
             "momentum_rate", "momentum_rate_jacobian", "nonholonomic", "nonholonomic_dq",
             "transport", "transport_dq"))
