"""Stormer-Verlet: velocity Verlet for constant H, the generalized leapfrog for H(q).

In (q, p) with p = H(q) v and f(q, v, t) = dT/dq - dV/dq + Q (generated ``momentum_rate``), one
step is kick(h/2), drift, kick(h/2) (Hairer-Lubich-Wanner, GNI, sec. VI.3, eq. (3.4)):

    H(q) u = p + h/2 f(q, u, t)                       implicit in u  (Newton)
    p* = H(q) u
    H(q+) w = p*,  q+ = q + h/2 (u + w)               implicit in w  (Newton)
    p+ = p* + h/2 f(q+, w, t + h),   v+ = H(q+)^-1 p+ explicit

i.e. symplectic Euler A over h/2 composed with its adjoint. Order 2, symmetric, symplectic in
(q, p) for any H(q) (to the Newton tolerance). On x'' = -omega^2 x its step matrix has
eigenvalues on the unit circle for tau = h omega < 2 (rho = 1) and a real pair with rho > 1
beyond: Verlet is stable only for tau < 2.

When H is constant and forces are velocity-free (generated MASS_IS_CONSTANT and
FORCES_VELOCITY_FREE, settings.newton_always off: options.explicit_path) both implicit parts are
linear and the scheme is exactly velocity Verlet, run explicitly with one force evaluation per
step (the acceleration at the end of a step is cached, workspace ``acc``, for the next):

    v* = v + h/2 a(q, t),   q+ = q + h v*,   v+ = v* + h/2 a(q+, t + h)
"""

import math
from collections import namedtuple

import numpy as np
from ...jit.cache import njit

from ..core.legendre import accel, momentum_from_velocity

from ..core.options import FAST, explicit_path, inline_step

from ..core.solve import matvec
from ..core.method_spec import PartitionedSettings, Spec
from ..core.partitioned import (GUESS_DEGREE, begin_step, best_degree, end_step, extrapolate, push,
                          solve_drift, solve_kick)
from ..core.status import OK

#: Scratch of one run (n,): the cached acceleration acc (explicit path, kept between steps), the
#: kick's and drift's unknowns u, w (u is v* on the explicit path), residual R, momentum rate f
#: (a(q+) on the explicit path), solver scratch s, pivots, q+, v+, p_half (p* then p+);
#: (n, n): H, the Newton matrix A, df/dq, df/dv, d(H w)/dq; what one step leaves the next
#: (partitioned.begin_step): history (GUESS_DEGREE + 1, n) earlier kick solutions, drifts
#: (GUESS_DEGREE + 1, n) earlier drift-minus-kick solutions w - u, carried (4,) int: H(q)
#: factored, solutions kept, degrees of the next kick's and drift's guesses.
Workspace = namedtuple("Workspace",
                       "acc u w R f s piv q_new v_new p_half H A Jq Jqd dHw history drifts carried")


@njit
def workspace(kern, n):
    """Allocated once per run by run_loop.run_loop."""
    return Workspace(np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n),
                     np.zeros(n), np.zeros(n, np.int64), np.zeros(n), np.zeros(n), np.zeros(n),
                     np.zeros((n, n)), np.zeros((n, n)), np.zeros((n, n)), np.zeros((n, n)),
                     np.zeros((n, n)), np.zeros((GUESS_DEGREE + 1, n)),
                     np.zeros((GUESS_DEGREE + 1, n)), np.zeros(4, np.int64))


@njit(**FAST)
def prepare(kern, q, v, mom, t, p, settings, ws, extra):
    """Explicit path: cache a(q, t) in ws.acc. Newton path: carry p = H(q) v."""
    if explicit_path(kern, settings):
        return accel(kern, q, v, t, p, ws.H, ws.acc)
    momentum_from_velocity(kern, q, v, t, p, ws.H, mom)
    ws.carried[0] = ws.carried[1] = ws.carried[2] = ws.carried[3] = 0
    return OK


# step_explicit and step_newton are inlined into step (and into composition.composed_step's
# loop): as separate functions, each call passes the 15 arrays of the workspace, which would
# cost about 30 ns per call on the pendulum, more than half of an explicit verlet step there.
@njit(inline="always")
def step_explicit(kern, q, v, t, h, p, ws):
    """The explicit path's step (velocity Verlet, cached acceleration); returns status."""
    n = q.shape[0]
    acc, v_half, q_new, acc_new = ws.acc, ws.u, ws.q_new, ws.f
    for i in range(n):
        v_half[i] = v[i] + 0.5 * h * acc[i]
        q_new[i] = q[i] + h * v_half[i]
    # Forces are velocity-free here, so a(q+) does not depend on the velocity passed.
    status = accel(kern, q_new, v_half, t + h, p, ws.H, acc_new)
    if status != OK:
        return status
    for i in range(n):
        q[i] = q_new[i]
        v[i] = v_half[i] + 0.5 * h * acc_new[i]
        acc[i] = acc_new[i]
    return OK


@njit(inline="always")
def step_newton(kern, q, v, mom, t, h, p, settings, ws, contraction_stop):
    """The Newton path's step; returns (status, Newton iterations, residual). The kick's guess
    is extrapolated from the earlier steps' solutions (partitioned.begin_step), the drift's is
    u plus the extrapolation of the earlier differences w - u (on the 16-link chain 5.76 against
    8.90 iterations per step with the last difference alone): ws holds a sequence of steps of
    one size (composition.py gives each of its substeps its own). contraction_stop: the Newton
    stopping rule (newton.solve_simplified): True for verlet's own step, False in a composition."""
    n = kern.N_COORDS       # a compile-time constant in the module's glue (core/options.py, "Loop bounds")
    tol, max_iter = settings.newton_tol, settings.max_iter
    u, w, f, q_new, v_new, p_half = ws.u, ws.w, ws.f, ws.q_new, ws.v_new, ws.p_half
    status, kept = begin_step(kern, q, v, t, p, ws.H, ws.A, ws.piv, u, ws.history, ws.carried)
    if status != OK:
        return status, 0, 0.0
    status, it1, res1 = solve_kick(kern, q, mom, t, 0.5 * h, p, tol, max_iter, ws.H, ws.A,
                                   ws.Jq, ws.Jqd, ws.piv, u, ws.R, f, ws.s, contraction_stop)
    if status != OK:
        return status, it1, res1
    ws.carried[2] = best_degree(ws.history, u, kept, v, n)
    matvec(ws.H, u, p_half, n)                  # p* = H(q) u + b (ws.H holds H(q))
    if kern.TRANSPORT:
        kern.transport(q, t, p, p_half)
    drifts, degree = ws.drifts, min(ws.carried[3], kept - 1)
    for i in range(n):
        w[i] = u[i] + (extrapolate(drifts, degree, i) if kept >= 1 else 0.0)
    status, it2, res2 = solve_drift(kern, q, u, p_half, 0.5 * h, t + h, p, tol, max_iter, ws.H, ws.A,
                                    ws.dHw, ws.piv, w, ws.R, q_new, ws.s, contraction_stop)
    iters, resid = it1 + it2, max(res1, res2)
    if status != OK:
        return status, iters, resid
    for i in range(n):
        ws.R[i] = w[i] - u[i]
    if kept >= 1:
        ws.carried[3] = best_degree(drifts, ws.R, kept, drifts[0], n)
    push(drifts, ws.R, n)
    kern.momentum_rate(q_new, w, t + h, p, f)
    for i in range(n):
        p_half[i] += 0.5 * h * f[i]            # now p+
    # (solve_drift leaves H(q+) in ws.H, at q+ to the Newton tolerance)
    status = end_step(kern, q_new, p_half, t + h, p, ws.H, ws.A, ws.piv, v_new, ws.s, ws.carried,
                      kept, ws.history.shape[0])
    if status != OK:
        return status, iters, resid
    for i in range(n):
        q[i], v[i], mom[i] = q_new[i], v_new[i], p_half[i]
    return OK, iters, resid


@njit(inline=inline_step, **FAST)
def step(kern, q, v, mom, t, h, p, settings, ws, extra):
    """One step from (q, v, mom) at t, in place. Returns (status, Newton iterations, residual)."""
    if explicit_path(kern, settings):
        return step_explicit(kern, q, v, t, h, p, ws), 0, 0.0
    return step_newton(kern, q, v, mom, t, h, p, settings, ws, True)


def linear_step_matrix(tau):
    """The step matrix (2, 2) on x'' = -omega^2 x acting on (x, v / omega), tau = h omega:
    trace 2 - tau^2, determinant 1."""
    return np.array([[1 - tau**2 / 2, tau], [-tau * (1 - tau**2 / 4), 1 - tau**2 / 2]])


def linear_radius(tau):
    """Spectral radius of linear_step_matrix(tau): 1 while |trace / 2| = |1 - tau^2 / 2| <= 1
    (tau <= 2), else |c| + sqrt(c^2 - 1) with c = trace / 2."""
    c = 1.0 - tau**2 / 2
    return 1.0 if abs(c) <= 1.0 else abs(c) + math.sqrt(c * c - 1.0)


SPEC = Spec(
    name="verlet", order=2, family="partitioned", implicit=True, symplectic=True,
    symmetric=True,
    summary="velocity Verlet / generalized leapfrog",
    stable="stable for tau < 2", stable_tau=2.0, rho=linear_radius,
    settings=PartitionedSettings,
    kernels=("forward_dynamics", "mass_matrix", "mass_matvec_dq",
             "momentum_rate", "momentum_rate_jacobian", "transport", "transport_dq"))
