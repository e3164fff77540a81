"""Symplectic Euler (the variational integrator of L_d(q0, q1) = h L(q0, (q1 - q0)/h)).

In (q, p) with p = H(q) v, K(q, p) = 1/2 p^T H(q)^-1 p + V(q), and f = dT/dq - dV/dq + Q:

    H(q) u = p + h f(q, u, t)      (implicit in u when f depends on v; Newton)
    q+ = q + h u,   p+ = H(q) u,   v+ = H(q+)^-1 p+

This is symplectic Euler "A" (p implicit, q explicit): order 1, symplectic in (q, p) (exactly,
up to the Newton tolerance), not symmetric. Nonconservative forces enter as the forced discrete
Euler-Lagrange equations (h Q added to the momentum update).

When H is constant and forces are velocity-free (the generated flags MASS_IS_CONSTANT and
FORCES_VELOCITY_FREE, and settings[S_MODE] == 0) it reduces to the explicit kick-drift
v+ = v + h a(q, t), q+ = q + h v+: one force evaluation per step, no Newton.
"""

import sys

from numba import njit

from ..status import OK
from .spec import PartitionedSettings, Spec
from .base import (FAST, S_MAX_ITER, S_TOL, accel, explicit_path, momentum_from_velocity,
                   run_loop, velocity_from_momentum)
from .partitioned import solve_kick

_U, _R, _F, _S, _QN, _VN, _PN = 0, 1, 2, 3, 4, 5, 6     # work rows
_H, _A, _JQ, _JQD = 0, 1, 2, 3                          # mats


@njit(**FAST)
def prepare(kern, q, v, mom, t, p, settings, work, mats, piv):
    """Carry the momentum p = H(q) v between steps (Newton path only)."""
    if not explicit_path(kern, settings):
        momentum_from_velocity(kern, q, v, p, mats[_H], mom)
    return OK


@njit(**FAST)
def step(kern, q, v, mom, t, h, p, settings, work, mats, piv, extra):
    """One step from (q, v, mom) at t, in place. Returns (status, Newton iterations, residual)."""
    n = q.shape[0]
    if explicit_path(kern, settings):
        a = work[_F]
        status = accel(kern, q, v, t, p, mats[_H], a)
        if status != OK:
            return status, 0, 0.0
        for i in range(n):
            v[i] += h * a[i]
            q[i] += h * v[i]
        return OK, 0, 0.0
    u, q_new, v_new, p_new = work[_U], work[_QN], work[_VN], work[_PN]
    for i in range(n):
        u[i] = v[i]
    status, iters, resid = solve_kick(kern, q, mom, t, h, p, settings[S_TOL],
                                      int(settings[S_MAX_ITER]), mats[_H], mats[_A], mats[_JQ],
                                      mats[_JQD], piv, u, work[_R], work[_F], work[_S])
    if status != OK:
        return status, iters, resid
    H = mats[_H]
    for i in range(n):
        q_new[i] = q[i] + h * u[i]
        s = 0.0
        for j in range(n):
            s += H[i, j] * u[j]
        p_new[i] = s
    status = velocity_from_momentum(kern, q_new, p_new, p, mats[_A], v_new)
    if status != OK:
        return status, iters, resid
    for i in range(n):
        q[i], v[i], mom[i] = q_new[i], v_new[i], p_new[i]
    return OK, iters, resid


@njit(inline="always")
def run(kern, q0, v0, t0, h, n_steps, save_every, p, settings,
        out_t, out_q, out_v, out_stats, out_extra, out_last):
    """See base.run_loop."""
    return run_loop(_THIS, kern, q0, v0, t0, h, n_steps, save_every, p, settings,
                    out_t, out_q, out_v, out_stats, out_extra, out_last)


# This module as a value for run_loop (see base.py: modules, not dispatchers, are passed).
_THIS = sys.modules[__name__]

SPEC = Spec(
    name="symplectic_euler", order=1, family="partitioned", implicit=True, symplectic=True,
    symmetric=False,
    summary="symplectic Euler A in (q, p = H v)",
    stable="stable for tau < 2",
    settings=PartitionedSettings,
    kernels=("energy", "forward_dynamics", "mass_matrix", "momentum_rate", "momentum_rate_jacobian"))
