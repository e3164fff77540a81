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

import sys

from numba import njit

from ..status import OK
from . import newton
from .spec import NewtonSettings, Spec
from .base import FAST, S_MAX_ITER, S_TOL, run_loop

_V1, _Q1, _DV, _RHS, _R, _S = 0, 1, 2, 3, 4, 5     # work rows
_H, _A, _JQ, _JQD, _DHW = 0, 1, 2, 3, 4           # mats


@njit(**FAST)
def prepare(kern, q, v, mom, t, p, settings, work, mats, piv):
    """Nothing is carried between steps."""
    return OK


@njit(inline="always")
def assemble(kern, args, v1, R, A):
    """Newton system of the step (newton.solve): R (n,) <- R(v+), A (n, n) <- dR/dv+."""
    q, v, t1, h, p, q1, dv, rhs, H, Jq, Jqd, dHw = args
    n = q.shape[0]
    for i in range(n):
        q1[i] = q[i] + h * v1[i]
        dv[i] = v1[i] - v[i]
    kern.dynamics(q1, v1, t1, p, H, rhs)
    kern.rhs_jacobian(q1, v1, t1, p, Jq, Jqd)
    kern.mass_matvec_dq(q1, dv, p, dHw)
    for i in range(n):
        s = -h * rhs[i]
        for j in range(n):
            s += H[i, j] * dv[j]
            A[i, j] = H[i, j] + h * dHw[i, j] - h * h * Jq[i, j] - h * Jqd[i, j]
        R[i] = s


@njit(**FAST)
def step(kern, q, v, mom, t, h, p, settings, work, mats, piv, extra):
    """One step from (q, v) at t, in place. Returns (status, Newton iterations, residual)."""
    n = q.shape[0]
    v1 = work[_V1]
    for i in range(n):
        v1[i] = v[i]
    args = (q, v, t + h, h, p, work[_Q1], work[_DV], work[_RHS], mats[_H], mats[_JQ],
            mats[_JQD], mats[_DHW])
    status, iters, resid = newton.solve(_THIS, kern, args, v1, work[_R], mats[_A], piv,
                                        work[_S], settings[S_TOL], int(settings[S_MAX_ITER]))
    if status == OK:
        for i in range(n):
            q[i] += h * v1[i]
            v[i] = v1[i]
    return status, iters, resid


@njit(inline="always")
def run(kern, q0, v0, t0, h, n_steps, save_every, p, settings,
        out_t, out_q, out_v, out_stats, out_extra, out_last):
    """See base.run_loop."""
    return run_loop(_THIS, kern, q0, v0, t0, h, n_steps, save_every, p, settings,
                    out_t, out_q, out_v, out_stats, out_extra, out_last)


# This module as a value for run_loop (see base.py: modules, not dispatchers, are passed).
_THIS = sys.modules[__name__]

SPEC = Spec(
    name="implicit_euler", order=1, family="implicit", implicit=True, symplectic=False,
    symmetric=False,
    summary="backward Euler (L-stable)",
    stable="stable for every tau, damping (rho = 1/sqrt(1 + tau^2))",
    settings=NewtonSettings,
    kernels=("dynamics", "energy", "mass_matvec_dq", "rhs_jacobian"))
