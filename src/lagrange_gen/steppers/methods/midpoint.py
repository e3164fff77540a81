"""The midpoint variational integrator (implicit midpoint in the Lagrangian setting).

Discrete Lagrangian L_d(q0, q1) = h L((q0 + q1)/2, (q1 - q0)/h); with the midpoint forcing
h/2 Q at both ends (forced discrete Lagrange-d'Alembert) and p = H(q) v, f = dT/dq - dV/dq + Q
(generated ``momentum_rate``) one step is, with the unknown mean velocity vb = (q+ - q)/h and
qb = q + h/2 vb:

    R(vb) = H(qb) vb - h/2 f(qb, vb, t + h/2) - p = 0          (Newton on vb)
    q+ = q + h vb,   p+ = p + h f(qb, vb, t + h/2),   v+ = H(q+)^-1 p+

Order 2, symmetric (L_d(q0, q1, h) = -L_d(q1, q0, -h)), symplectic in (q, p) for any H(q) (to
the Newton tolerance). On a linear system with constant H it is exactly the implicit midpoint
rule: on x'' = -omega^2 x the step matrix is a rotation (Cayley transform), rho = 1 for every
tau = h omega, with phase 2 atan(tau/2) per step (A-stable, no numerical damping).

Rheonomic models: H, b and f are evaluated at tm = t + h/2 and v+ = H(q+, t + h)^-1 (p+ - b);
with a term T1 = b(q, t) . v in T, p is the canonical momentum H v + b and R gains b(qb, tm)
(its Jacobian h/2 db/dq), so the scheme stays the variational one for L = T - V.

Newton uses the exact Jacobian
    dR/dvb = H(qb) + h/2 d(H vb)/dq - h^2/4 df/dq - h/2 df/dv
from ``mass_matvec_dq`` and ``momentum_rate_jacobian``.
"""

import math
import sys
from collections import namedtuple

import numpy as np
from ...jit.cache import njit

from ..core import newton
from ..core.legendre import momentum_from_velocity, velocity_from_momentum
from ..core.options import FAST, inline_step
from ..core.method_spec import NewtonSettings, Spec
from ..core.status import OK

#: Scratch of one run: the Newton unknown vb and midpoint qb, residual R, momentum rate f,
#: solver scratch s and pivots, the new state; H, the Newton matrix A, df/dq, df/dv, d(H vb)/dq.
Workspace = namedtuple("Workspace", "vb qb R f s piv q_new v_new p_new H A Jq Jqd dHw")


@njit
def workspace(kern, n):
    """Allocated once per run by run_loop.run_loop."""
    return Workspace(np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n),
                     np.zeros(n, np.int64), np.zeros(n), np.zeros(n), np.zeros(n),
                     np.zeros((n, n)), np.zeros((n, n)), np.zeros((n, n)), np.zeros((n, n)),
                     np.zeros((n, n)))


@njit(**FAST)
def prepare(kern, q, v, mom, t, p, settings, ws, extra):
    """Carry the momentum p = H(q) v between steps."""
    momentum_from_velocity(kern, q, v, t, p, ws.H, mom)
    return OK


@njit(inline="always")
def assemble(kern, args, vb, R, A):
    """Newton system of the step (newton.solve): R (n,) <- R(vb), A (n, n) <- dR/dvb."""
    q, mom, tm, hh, p, qb, f, H, Jq, Jqd, dHw = args
    n = kern.N_COORDS       # (core/options.py, "Loop bounds")
    for i in range(n):
        qb[i] = q[i] + hh * vb[i]
    kern.mass_matrix(qb, tm, p, H)
    kern.mass_matvec_dq(qb, vb, tm, p, dHw)
    kern.momentum_rate(qb, vb, tm, p, f)
    kern.momentum_rate_jacobian(qb, vb, tm, p, Jq, Jqd)
    if kern.TRANSPORT:                        # p = H v + b: R gains b(qb), dR/dvb h/2 db/dq
        kern.transport_dq(qb, tm, p, dHw)
    for i in range(n):
        s = -mom[i] - hh * f[i]
        for j in range(n):
            s += H[i, j] * vb[j]
            A[i, j] = H[i, j] + hh * dHw[i, j] - hh * hh * Jq[i, j] - hh * Jqd[i, j]
        R[i] = s
    if kern.TRANSPORT:
        kern.transport(qb, tm, p, R)


@njit(inline=inline_step, **FAST)
def step(kern, q, v, mom, t, h, p, settings, ws, extra):
    """One step from (q, v, mom) at t, in place. Returns (status, Newton iterations, residual)."""
    n = kern.N_COORDS       # (core/options.py, "Loop bounds")
    vb, qb, f = ws.vb, ws.qb, ws.f
    q_new, v_new, p_new = ws.q_new, ws.v_new, ws.p_new
    tm = t + 0.5 * h
    for i in range(n):
        vb[i] = v[i]
    args = (q, mom, tm, 0.5 * h, p, qb, f, ws.H, ws.Jq, ws.Jqd, ws.dHw)
    status, iters, resid = newton.solve(_THIS, kern, args, vb, ws.R, ws.A, ws.piv, ws.s,
                                        settings.newton_tol, settings.max_iter, kern.N_COORDS)
    if status != OK:
        return status, iters, resid
    for i in range(n):
        qb[i] = q[i] + 0.5 * h * vb[i]
        q_new[i] = q[i] + h * vb[i]
    kern.momentum_rate(qb, vb, tm, p, f)      # at the converged vb: p+ = p + h f exactly
    for i in range(n):
        p_new[i] = mom[i] + h * f[i]
    status = velocity_from_momentum(kern, q_new, p_new, t + h, p, ws.A, v_new)
    if status != OK:
        return status, iters, resid
    for i in range(n):
        q[i], v[i], mom[i] = q_new[i], v_new[i], p_new[i]
    return OK, iters, resid


# This module as a value for newton.solve (see core/run_loop.py: modules, not dispatchers, are passed).
_THIS = sys.modules[__name__]

def linear_radius(tau):
    """rho of the step matrix on x'' = -omega^2 x: a Cayley transform, rho = 1 for every tau."""
    return 1.0


def linear_phase(tau):
    """Phase per step on x'' = -omega^2 x: 2 atan(tau / 2) (exact: tau)."""
    return 2.0 * math.atan(tau / 2.0)


SPEC = Spec(
    name="midpoint", order=2, family="implicit", implicit=True, symplectic=True, symmetric=True,
    summary="midpoint variational integrator (A-stable)",
    stable="linearly stable for every tau (rho = 1), accurate only for tau << 1",
    stable_tau=math.inf, rho=linear_radius, phase=linear_phase,
    settings=NewtonSettings,
    kernels=("mass_matrix", "mass_matvec_dq", "momentum_rate",
             "momentum_rate_jacobian", "transport", "transport_dq"))
