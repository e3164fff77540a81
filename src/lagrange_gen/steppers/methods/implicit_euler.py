"""Implicit (backward) Euler on the first-order system, without forming H^-1.

With rhs = Q - h - g (generated ``dynamics``), one step solves for v+ (Newton):

    R(v+) = H(q+) (v+ - v) - h rhs(q+, v+, t + h) = 0,    q+ = q + h v+

Order 1, not symmetric, not symplectic; L-stable: on x'' = -omega^2 x the step matrix has
eigenvalues 1/(1 +- i tau), spectral radius 1/sqrt(1 + tau^2) -> 0 as tau -> inf, so stiff modes
are damped out. This is the stepper of the nonsmooth elements (exact for the play operator).

Newton uses the exact Jacobian
    dR/dv+ = H(q+) + h d(H w)/dq |_{w = v+ - v} - h^2 d rhs/dq - h d rhs/dv
from ``mass_matvec_dq`` and ``rhs_jacobian``.
"""

import math
import sys
from collections import namedtuple

import numpy as np
from ...jit.cache import njit

from ..core import newton
from ..core.options import FAST, inline_step
from ..core.method_spec import NewtonSettings, Spec
from ..core.status import OK

#: Scratch of one run: the Newton unknown v1 = v+, q1 = q+, dv = v+ - v, rhs, residual R, solver
#: scratch s and pivots; H, the Newton matrix A, d rhs/dq, d rhs/dv, d(H w)/dq.
Workspace = namedtuple("Workspace", "v1 q1 dv rhs R s piv H A Jq Jqd dHw")


@njit
def workspace(kern, n):
    """Allocated once per run by run_loop.run_loop."""
    return Workspace(np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n),
                     np.zeros(n), np.zeros(n, np.int64), np.zeros((n, n)), np.zeros((n, n)),
                     np.zeros((n, n)), np.zeros((n, n)), np.zeros((n, n)))


@njit(**FAST)
def prepare(kern, q, v, mom, t, p, settings, ws, extra):
    """Nothing is carried between steps."""
    return OK


@njit(inline="always")
def assemble(kern, args, v1, R, A):
    """Newton system of the step (newton.solve): R (n,) <- R(v+), A (n, n) <- dR/dv+."""
    q, v, t1, h, p, q1, dv, rhs, H, Jq, Jqd, dHw = args
    n = kern.N_COORDS       # (core/options.py, "Loop bounds")
    for i in range(n):
        q1[i] = q[i] + h * v1[i]
        dv[i] = v1[i] - v[i]
    kern.dynamics(q1, v1, t1, p, H, rhs)
    kern.rhs_jacobian(q1, v1, t1, p, Jq, Jqd)
    kern.mass_matvec_dq(q1, dv, t1, p, dHw)
    for i in range(n):
        s = -h * rhs[i]
        for j in range(n):
            s += H[i, j] * dv[j]
            A[i, j] = H[i, j] + h * dHw[i, j] - h * h * Jq[i, j] - h * Jqd[i, j]
        R[i] = s


@njit(inline=inline_step, **FAST)
def step(kern, q, v, mom, t, h, p, settings, ws, extra):
    """One step from (q, v) at t, in place. Returns (status, Newton iterations, residual)."""
    n = kern.N_COORDS       # (core/options.py, "Loop bounds")
    v1 = ws.v1
    for i in range(n):
        v1[i] = v[i]
    args = (q, v, t + h, h, p, ws.q1, ws.dv, ws.rhs, ws.H, ws.Jq, ws.Jqd, ws.dHw)
    status, iters, resid = newton.solve(_THIS, kern, args, v1, ws.R, ws.A, ws.piv, ws.s,
                                        settings.newton_tol, settings.max_iter, kern.N_COORDS)
    if status == OK:
        for i in range(n):
            q[i] += h * v1[i]
            v[i] = v1[i]
    return status, iters, resid


# This module as a value for newton.solve (see core/run_loop.py: modules, not dispatchers, are passed).
_THIS = sys.modules[__name__]

def linear_radius(tau):
    """rho of the step matrix (inverse of [[1, -tau], [tau, 1]]) on x'' = -omega^2 x:
    1 / sqrt(1 + tau^2) (L-stable: -> 0 as tau -> inf)."""
    return 1.0 / math.sqrt(1.0 + tau * tau)


SPEC = Spec(
    name="implicit_euler", order=1, family="implicit", implicit=True, symplectic=False,
    symmetric=False,
    summary="backward Euler (L-stable)",
    stable="stable for every tau, damping (rho = 1/sqrt(1 + tau^2))",
    stable_tau=math.inf, rho=linear_radius,
    settings=NewtonSettings,
    kernels=("dynamics", "mass_matvec_dq", "rhs_jacobian"))
