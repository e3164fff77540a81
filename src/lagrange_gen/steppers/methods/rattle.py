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

Explicit path (constant H, velocity-free forces, not settings.newton_always: Cartesian models), the
classical RATTLE of Andersen (1983) with one force evaluation per step:

    v* = v + h/2 a(q),   q+ = q + h v* + h^2/2 M^-1 J(q)^T lam,   Phi(q+) = 0
    v+ = v* + h/2 a(q+) + h/2 M^-1 J(q+)^T mu,   J(q+) v+ = 0

Newton on kappa = h^2/2 lam (a displacement of q+) with the exact Jacobian J(q+) M^-1 J(q)^T
(m x m), started from the previous step's multiplier; M is factored and J(q) computed once per
run (then J(q+) is kept for the next step). The reported |Phi| is evaluated at the accepted q+.

Newton path (H(q) or velocity-dependent forces): one Newton iteration on the whole position
stage (u, w, nu = h/2 lam), size 2n + m, with the exact Jacobian

    [[H(q) - h/2 df/dv(q, u),  0,                 -J(q)^T  ],
     [h/2 D - H(q),            H(q+) + h/2 D,      0       ],     D = d(H(q) w)/dq at q+
     [J(q+)/2,                 J(q+)/2,            0       ]]

for the residuals (kick, drift, Phi(q+)/h). Both Newton iterations are newton.solve's (LU with
partial pivoting, its stopping rule on the increment): a singular Newton matrix (on the explicit
path J M^-1 J^T: redundant constraints) is SINGULAR_NEWTON, NON_FINITE when it holds NaN or inf;
a singular J H^-1 J^T in the velocity projection is SINGULAR_MASS.
"""

from collections import namedtuple

import numpy as np
from ...jit.cache import njit

from ..core import newton
from ..core.legendre import momentum_from_velocity, subtract_transport
from ..core.options import FAST, explicit_path, inline_step
from ..core.constrained import SAVED, constraint_rate, finish_momentum_step, project, record, solve_rows
from ..core.linalg import cholesky_inplace, cholesky_solve_inplace
from ..core.method_spec import PartitionedSettings, Spec
from ..core.status import OK, SINGULAR_MASS

#: Scratch of one run (n coordinates, m constraints); every array costs a little in each call of
#: step (numba passes the workspace's arrays one by one), so the two paths share where they can.
#: Explicit path: the Newton unknown kappa and its residual Fk (m) (the Newton matrix is S, the
#: scratch and pivots those of the Newton path, longer than m); the cached acceleration acc, the
#: half-step velocity vh, the unconstrained position z (n); M: chol(M), kept for the run.
#: Newton path: the unknown x = (u, w, nu), residual F, scratch s, pivots (2n + m), matrix K;
#: the momentum pt (n); M: H(q); H(q+), df/dq, df/dv, d(H w)/dq at q+ (n, n).
#: Both: the new state q1, v1, the force f (n); Phi, gamma, the end impulse eta (m); J(q) (from
#: prepare, then J(q+) of the previous step), J(q+), the rows H^-1 J^T Y, T (m, n) (explicit
#: path: Y = M^-1 J(q)^T, kept the same way); S (m, m) the Schur complement J H^-1 J^T.
Workspace = namedtuple("Workspace", "kap Fk acc vh z x F s piv K pt M H1 Jq Jqd D q1 v1 f phi gam "
                                    "eta Ja Jb Y T S")


@njit
def workspace(kern, n):
    """Allocated once per run by run_loop.run_loop."""
    m = kern.N_CONSTRAINTS
    N = 2 * n + m
    return Workspace(np.zeros(m), np.zeros(m), np.zeros(n), np.zeros(n), np.zeros(n),
                     np.zeros(N), np.zeros(N), np.zeros(N), np.zeros(N, np.int64),
                     np.zeros((N, N)), np.zeros(n), np.zeros((n, n)), np.zeros((n, n)),
                     np.zeros((n, n)), np.zeros((n, n)), np.zeros((n, n)), np.zeros(n),
                     np.zeros(n), np.zeros(n), np.zeros(m), np.zeros(m), np.zeros(m),
                     np.zeros((m, n)), np.zeros((m, n)), np.zeros((m, n)), np.zeros((m, n)),
                     np.zeros((m, m)))


@njit(**FAST)
def prepare(kern, q, v, mom, t, p, settings, ws, extra):
    """J(q) into ws.Ja (then each step leaves J(q+) there for the next). Explicit path: factor
    the constant M once (ws.M), cache a(q, t) in ws.acc and the rows M^-1 J(q)^T in ws.Y.
    Newton path: carry p = H(q) v."""
    kern.constraints(q, v, t, p, ws.phi, ws.Ja, ws.gam)
    if explicit_path(kern, settings):
        L, acc = ws.M, ws.acc
        kern.dynamics(q, v, t, p, L, acc)
        if not cholesky_inplace(L):
            return SINGULAR_MASS
        cholesky_solve_inplace(L, acc)
        solve_rows(L, ws.Ja, ws.Y)
        return OK
    momentum_from_velocity(kern, q, v, t, p, ws.M, mom)
    return OK


@njit(inline="always")
def assemble_multiplier(kern, args, kap, F, K):
    """Newton system of the explicit path: F (m) <- Phi(q+) at q+ = z + Y^T kappa, K (m, m) <-
    J(q+) Y^T = J(q+) M^-1 J(q)^T."""
    z, vh, t1, p, Y, q1, phi, Jb, gam = args
    n, m = z.shape[0], kap.shape[0]
    for i in range(n):
        s = z[i]
        for k in range(m):
            s += Y[k, i] * kap[k]
        q1[i] = s
    kern.constraints(q1, vh, t1, p, phi, Jb, gam)
    for i in range(m):
        F[i] = phi[i]
        for k in range(m):
            s = 0.0
            for j in range(n):
                s += Jb[i, j] * Y[k, j]
            K[i, k] = s


@njit(inline="always")
def _step_explicit(kern, q, v, t, h, p, settings, ws, extra):
    n, m = q.shape[0], kern.N_CONSTRAINTS
    L, acc, vh, z, q1, v1, f = ws.M, ws.acc, ws.vh, ws.z, ws.q1, ws.v1, ws.f
    kap, phi, Ja, Jb, Y, T = ws.kap, ws.phi, ws.Ja, ws.Jb, ws.Y, ws.T
    hh = 0.5 * h
    for i in range(n):
        vh[i] = v[i] + hh * acc[i]
        z[i] = q[i] + h * vh[i]
    for k in range(m):                        # Y: rows M^-1 J(q)_k^T, q+ = z + Y^T kappa
        kap[k] = hh * h * extra[k]
    status, iters, resid = newton.solve(_MULTIPLIER, kern, (z, vh, t + h, p, Y, q1, phi, Jb, ws.gam),
                                        kap, ws.Fk, ws.S, ws.piv, ws.s,
                                        settings.newton_tol, settings.max_iter, kap.shape[0])
    if status != OK:
        return status, iters, resid
    for i in range(n):                        # q+ and v_1/2 = v* + h/2 M^-1 J(q)^T lam
        s = 0.0
        for k in range(m):
            s += Y[k, i] * kap[k]
        q1[i] = z[i] + s
        vh[i] += s / h
    kern.constraints(q1, vh, t + h, p, phi, Jb, ws.gam)
    # Velocity stage: forces are velocity-free here, so a(q+) does not depend on vh.
    kern.dynamics(q1, vh, t + h, p, ws.H1, f)
    cholesky_solve_inplace(L, f)
    for i in range(n):
        v1[i] = vh[i] + hh * f[i]
    solve_rows(L, Jb, T)
    constraint_rate(kern, q1, t + h, p, ws.gam)        # gam: dPhi/dt from here on
    if not project(Jb, T, v1, ws.S, ws.eta, ws.gam):   # eta = h/2 mu
        return SINGULAR_MASS, iters, resid
    for i in range(n):
        q[i], v[i], acc[i] = q1[i], v1[i], f[i]
    for k in range(m):
        extra[k] = ws.eta[k] / hh
        for j in range(n):
            Ja[k, j], Y[k, j] = Jb[k, j], T[k, j]       # J(q), M^-1 J(q)^T of the next step
    record(extra, m, phi, Jb, v, ws.gam)
    return OK, iters, resid


@njit(inline="always")
def assemble_position(kern, args, x, F, K):
    """Newton system of the Newton path: F (2n + m) <- (kick, drift, Phi(q+)/h) at
    x = (u, w, nu), K its Jacobian (module docstring)."""
    q, mom, pm, t, h, p, q1, f, H0, H1, Jq, Jqd, D, phi, Ja, Jb, gam = args
    n, m = q.shape[0], phi.shape[0]
    u, w = x[:n], x[n:2 * n]
    hh = 0.5 * h
    for i in range(n):
        q1[i] = q[i] + hh * (u[i] + w[i])
    kern.momentum_rate(q, u, t, p, f)
    kern.momentum_rate_jacobian(q, u, t, p, Jq, Jqd)
    kern.mass_matrix(q1, t + h, p, H1)
    kern.mass_matvec_dq(q1, w, t + h, p, D)
    kern.constraints(q1, w, t + h, p, phi, Jb, gam)
    if kern.TRANSPORT:                        # p = H v + b: the drift conserves H u + b
        kern.transport_dq(q1, t + h, p, D)
    for i in range(n):
        # pm = p - b(q, t) (see _step_newton; pm = p when T1 = 0): the kick H(q) u + b(q) = p +
        # h/2 f + J^T nu and, once b(q+) is added below, the drift residual
        # rb = H(q+) w + b(q+) - (H(q) u + b(q)).
        ra = -pm[i] - hh * f[i]
        rb = pm[i] - mom[i]
        for j in range(n):
            ra += H0[i, j] * u[j]
            rb += H1[i, j] * w[j] - H0[i, j] * u[j]
            K[i, j] = H0[i, j] - hh * Jqd[i, j]
            K[i, n + j] = 0.0
            K[n + i, j] = hh * D[i, j] - H0[i, j]
            K[n + i, n + j] = H1[i, j] + hh * D[i, j]
        for k in range(m):
            ra -= Ja[k, i] * x[2 * n + k]
            K[i, 2 * n + k] = -Ja[k, i]
            K[n + i, 2 * n + k] = 0.0
        F[i] = ra
        F[n + i] = rb
    for k in range(m):
        F[2 * n + k] = phi[k] / h
        for j in range(n):
            K[2 * n + k, j] = 0.5 * Jb[k, j]
            K[2 * n + k, n + j] = 0.5 * Jb[k, j]
        for j in range(m):
            K[2 * n + k, 2 * n + j] = 0.0
    if kern.TRANSPORT:
        kern.transport(q1, t + h, p, F[n:2 * n])


@njit(inline="always")
def _step_newton(kern, q, v, mom, t, h, p, settings, ws, extra):
    n, m = q.shape[0], kern.N_CONSTRAINTS
    x, q1, f, pt, H0 = ws.x, ws.q1, ws.f, ws.pt, ws.M
    hh = 0.5 * h
    kern.mass_matrix(q, t, p, H0)
    for i in range(n):
        x[i] = v[i]
        x[n + i] = v[i]
    for k in range(m):
        x[2 * n + k] = hh * extra[k]          # nu from the previous step's multiplier
    # pt (free until the end of the step) holds p - b(q, t) for the Newton system (assemble).
    for i in range(n):
        pt[i] = mom[i]
    subtract_transport(kern, q, t, p, pt)
    args = (q, mom, pt, t, h, p, q1, f, H0, ws.H1, ws.Jq, ws.Jqd, ws.D, ws.phi, ws.Ja, ws.Jb,
            ws.gam)
    status, iters, resid = newton.solve(_POSITION, kern, args, x, ws.F, ws.K, ws.piv, ws.s,
                                        settings.newton_tol, settings.max_iter, x.shape[0])
    if status != OK:
        return status, iters, resid
    u, w = x[:n], x[n:2 * n]
    for i in range(n):
        q1[i] = q[i] + hh * (u[i] + w[i])
    kern.momentum_rate(q1, w, t + h, p, f)
    for i in range(n):
        s = hh * f[i] + mom[i] - pt[i]        # b(q, t) (pt holds p - b)
        for j in range(n):
            s += H0[i, j] * u[j]              # H(q) u + b = p + h/2 f + J^T nu, exactly
        pt[i] = s
    status = finish_momentum_step(kern, q, v, mom, q1, t + h, pt, p, hh, w, ws.phi, ws.Jb, ws.gam,
                                  ws.Y, ws.H1, ws.S, ws.eta, ws.v1, extra, ws.Ja)
    return status, iters, resid


@njit(inline=inline_step, **FAST)
def step(kern, q, v, mom, t, h, p, settings, ws, extra):
    """One step from (q, v, mom) at t, in place. Returns (status, Newton iterations, residual)."""
    if explicit_path(kern, settings):
        return _step_explicit(kern, q, v, t, h, p, settings, ws, extra)
    return _step_newton(kern, q, v, mom, t, h, p, settings, ws, extra)


# The two Newton systems as modules for newton.solve (see newton.py: modules, not dispatchers).
_MULTIPLIER = newton.problem(__name__ + "._multiplier", assemble_multiplier)
_POSITION = newton.problem(__name__ + "._position", assemble_position)


SPEC = Spec(
    name="rattle", order=2, family="constrained", implicit=True, symplectic=True,
    symmetric=True,
    summary="constrained Verlet, Newton on the multipliers",
    constraints=True,
    saved=SAVED, constraint_drift="none",
    settings=PartitionedSettings,
    kernels=("constraint_rate", "constraints", "dynamics", "mass_matrix", "mass_matvec_dq",
             "momentum_rate", "momentum_rate_jacobian", "transport", "transport_dq"))
