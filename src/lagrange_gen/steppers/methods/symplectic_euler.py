"""Symplectic Euler (the variational integrator of L_d(q0, q1) = h L(q0, (q1 - q0)/h)).

In (q, p) with p = H(q) v, K(q, p) = 1/2 p^T H(q)^-1 p + V(q), and f = dT/dq - dV/dq + Q:

    H(q) u = p + h f(q, u, t)      (implicit in u when f depends on v; Newton)
    q+ = q + h u,   p+ = H(q) u,   v+ = H(q+)^-1 p+

This is symplectic Euler "A" (p implicit, q explicit): order 1, symplectic in (q, p) (exactly,
up to the Newton tolerance), not symmetric. Nonconservative forces enter as the forced discrete
Euler-Lagrange equations (h Q added to the momentum update).

When H is constant and forces are velocity-free (the generated flags MASS_IS_CONSTANT and
FORCES_VELOCITY_FREE, and settings.newton_always off: options.explicit_path) it reduces to the
explicit kick-drift v+ = v + h a(q, t), q+ = q + h v+: one force evaluation per step, no Newton.
"""

from collections import namedtuple

import numpy as np
from ...jit.cache import njit

from . import verlet
from ..core.legendre import accel, momentum_from_velocity
from ..core.options import FAST, explicit_path, inline_step
from ..core.solve import matvec
from ..core.method_spec import PartitionedSettings, Spec
from ..core.partitioned import GUESS_DEGREE, begin_step, best_degree, end_step, solve_kick
from ..core.status import OK

#: Scratch of one run (n,): the kick's unknown u, residual R, momentum rate f (the acceleration
#: on the explicit path), solver scratch s, pivots, the new state; (n, n): H, the Newton matrix
#: A, df/dq, df/dv; what one step leaves the next (partitioned.begin_step): history
#: (GUESS_DEGREE + 1, n) earlier kick solutions, carried (3,) int: H(q) factored, solutions
#: kept, degree of the next guess.
Workspace = namedtuple("Workspace", "u R f s piv q_new v_new p_new H A Jq Jqd history carried")


@njit
def workspace(kern, n):
    """Allocated once per run by run_loop.run_loop."""
    return Workspace(np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n, np.int64),
                     np.zeros(n), np.zeros(n), np.zeros(n), np.zeros((n, n)), np.zeros((n, n)),
                     np.zeros((n, n)), np.zeros((n, n)), np.zeros((GUESS_DEGREE + 1, n)),
                     np.zeros(3, np.int64))


@njit(**FAST)
def prepare(kern, q, v, mom, t, p, settings, ws, extra):
    """Carry the momentum p = H(q) v between steps (Newton path only)."""
    if not explicit_path(kern, settings):
        momentum_from_velocity(kern, q, v, t, p, ws.H, mom)
        ws.carried[0] = ws.carried[1] = ws.carried[2] = 0
    return OK


@njit(inline=inline_step, **FAST)
def step(kern, q, v, mom, t, h, p, settings, ws, extra):
    """One step from (q, v, mom) at t, in place. Returns (status, Newton iterations, residual)."""
    n = kern.N_COORDS       # a compile-time constant in the module's glue (core/options.py, "Loop bounds")
    if explicit_path(kern, settings):
        a = ws.f
        status = accel(kern, q, v, t, p, ws.H, a)
        if status != OK:
            return status, 0, 0.0
        for i in range(n):
            v[i] += h * a[i]
            q[i] += h * v[i]
        return OK, 0, 0.0
    u, q_new, v_new, p_new = ws.u, ws.q_new, ws.v_new, ws.p_new
    status, kept = begin_step(kern, q, v, t, p, ws.H, ws.A, ws.piv, u, ws.history, ws.carried)
    if status != OK:
        return status, 0, 0.0
    status, iters, resid = solve_kick(kern, q, mom, t, h, p, settings.newton_tol,
                                      settings.max_iter, ws.H, ws.A, ws.Jq, ws.Jqd, ws.piv, u,
                                      ws.R, ws.f, ws.s, True)
    if status != OK:
        return status, iters, resid
    ws.carried[2] = best_degree(ws.history, u, kept, v, n)
    for i in range(n):
        q_new[i] = q[i] + h * u[i]
    matvec(ws.H, u, p_new, n)                   # ws.H holds H(q)
    if kern.TRANSPORT:
        kern.transport(q, t, p, p_new)         # the canonical momentum H u + b
    kern.mass_matrix(q_new, t + h, p, ws.H)
    status = end_step(kern, q_new, p_new, t + h, p, ws.H, ws.A, ws.piv, v_new, ws.s, ws.carried,
                      kept, ws.history.shape[0])
    if status != OK:
        return status, iters, resid
    for i in range(n):
        q[i], v[i], mom[i] = q_new[i], v_new[i], p_new[i]
    return OK, iters, resid


SPEC = Spec(
    name="symplectic_euler", order=1, family="partitioned", implicit=True, symplectic=True,
    symmetric=False,
    summary="symplectic Euler A in (q, p = H v)",
    # Step matrix [[1 - tau^2, tau], [-tau, 1]]: verlet's trace and determinant, so its rho.
    stable="stable for tau < 2", stable_tau=2.0, rho=verlet.linear_radius,
    settings=PartitionedSettings,
    kernels=("forward_dynamics", "mass_matrix", "momentum_rate", "momentum_rate_jacobian", "transport"))
