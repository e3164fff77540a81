"""rk4 on the acceleration-level form of nonholonomic constraints: the reference for rolling.

A model with r velocity constraints A(q, t) v + b(q, t) = 0 (Lagrange-d'Alembert: the
constraint forces A^T mu do no virtual work on the allowed velocities) moves by

    H qdd = rhs + A^T mu,    A qdd = gamma      (gamma = -(dA/dt v + db/dt), generated
                                                  ``nonholonomic`` kernel)

whose accelerations come from the KKT system [[H, -A^T], [A, 0]] (a, mu) = (rhs, gamma), solved
through the Schur complement A H^-1 A^T (Cholesky): a = H^-1 rhs + H^-1 A^T mu with
(A H^-1 A^T) mu = gamma - A H^-1 rhs (constrained.project with the rate -gamma). The ODE in
(q, v) is integrated by the classical rk4 (explicit_rk's core with the rk4 tableau), as index1
does for holonomic constraints, what a user of sympy.physics.mechanics / PyDy with scipy does.

What it does not do: A v + b = 0 holds along the numerical solution only up to the local error
(nothing projects back), so |A v + b| drifts, like the energy of a conservative rolling system
(slowly: order 4). Both are saved so that a run shows them. The initial velocity must satisfy
the constraints: simulate projects v0 onto A v + b = 0 in the kinetic-energy metric and warns
(lagrange_gen.run.consistent.nonholonomic_start); prepare computes the first acceleration and
the multiplier of row 0.

``extra`` (SPEC.saved), r = kern.N_NONHOLONOMIC: mu (r), the constraint forces (multipliers) at
the end of the last step, and max_i |(A v + b)_i| there (1).
"""

import sys
from collections import namedtuple

import numpy as np
from ...jit.cache import njit

from ..core.options import FAST, inline_step
from ..core.constrained import max_abs_jv, project, solve_rows
from ..core.explicit_rk import RK4_A, RK4_B, RK4_C, rk_step
from ..core.linalg import cholesky_inplace, cholesky_solve_inplace
from ..core.method_spec import ExplicitSettings, Spec
from ..core.status import OK, SINGULAR_MASS

#: Scratch of one run (n coordinates, r nonholonomic constraints): the acceleration a0 at the
#: current state (cached from step to step), stage velocities and accelerations (4, n), stage q
#: qs, the new state (n); H (n, n); multipliers mu, b, gamma (r); A, H^-1 A^T rows Y (r, n);
#: Schur complement S (r, r).
Workspace = namedtuple("Workspace", "a0 stage_v stage_a qs q_new v_new H mu A b gam Y S")


@njit
def workspace(kern, n):
    """Allocated once per run by run_loop.run_loop."""
    r = kern.N_NONHOLONOMIC
    return Workspace(np.zeros(n), np.zeros((4, n)), np.zeros((4, n)), np.zeros(n), np.zeros(n),
                     np.zeros(n), np.zeros((n, n)), np.zeros(r), np.zeros((r, n)), np.zeros(r),
                     np.zeros(r), np.zeros((r, n)), np.zeros((r, r)))


@njit(**FAST)
def constrained_acceleration(kern, q, v, t, p, H, a, mu, A, b, gam, Y, S):
    """a (n,) and mu (r,) from the KKT system at (q, v, t); A (r, n) and b (r,) at (q, t) stay
    available to the caller (gam (r,) holds -gamma afterwards). Status OK or SINGULAR_MASS (H or
    A H^-1 A^T singular: dependent constraints)."""
    kern.dynamics(q, v, t, p, H, a)
    kern.nonholonomic(q, v, t, p, A, b, gam)
    if not cholesky_inplace(H):
        return SINGULAR_MASS
    cholesky_solve_inplace(H, a)              # unconstrained acceleration
    solve_rows(H, A, Y)
    for i in range(gam.shape[0]):
        gam[i] = -gam[i]                      # project() imposes A a + rate = 0
    if not project(A, Y, a, S, mu, gam):
        return SINGULAR_MASS
    return OK


@njit(**FAST)
def record(kern, extra, mu, A, v, b):
    """The saved fields: mu, then max|A v + b| (A, b at the state of v)."""
    r = kern.N_NONHOLONOMIC
    for k in range(r):
        extra[k] = mu[k]
    extra[r] = max_abs_jv(A, v, b)


@njit(**FAST)
def prepare(kern, q, v, mom, t, p, settings, ws, extra):
    """The acceleration at the initial state (the first stage of the first step) and the saved
    fields of row 0."""
    status = constrained_acceleration(kern, q, v, t, p, ws.H, ws.a0, ws.mu, ws.A, ws.b, ws.gam,
                                      ws.Y, ws.S)
    if status == OK:
        record(kern, extra, ws.mu, ws.A, v, ws.b)
    return status


@njit(**FAST)
def stage_acceleration(kern, ctx, q, v, t, a):
    """explicit_rk's callback: a (n,) from the KKT system; the stage multipliers go to scratch.
    ctx = (p, ws)."""
    p, ws = ctx
    return constrained_acceleration(kern, q, v, t, p, ws.H, a, ws.mu, ws.A, ws.b, ws.gam, ws.Y,
                                    ws.S)


@njit(inline=inline_step, **FAST)
def step(kern, q, v, mom, t, h, p, settings, ws, extra):
    """One rk4 step from (q, v) at t, in place. Returns (status, 0, 0.0)."""
    n = q.shape[0]
    a0, stage_a, q_new, v_new = ws.a0, ws.stage_a, ws.q_new, ws.v_new
    for i in range(n):
        stage_a[0, i] = a0[i]
    status = rk_step(_THIS, kern, (p, ws), RK4_A, RK4_B, RK4_C, q, v, t, h, ws.stage_v, stage_a,
                     ws.qs, q_new, v_new, True)
    if status != OK:
        return status, 0, 0.0
    # Acceleration and multiplier at the new state: reported now, first stage of the next step.
    status = constrained_acceleration(kern, q_new, v_new, t + h, p, ws.H, stage_a[0], ws.mu,
                                      ws.A, ws.b, ws.gam, ws.Y, ws.S)
    if status != OK:
        return status, 0, 0.0
    for i in range(n):
        q[i], v[i], a0[i] = q_new[i], v_new[i], stage_a[0, i]
    record(kern, extra, ws.mu, ws.A, v, ws.b)
    return OK, 0, 0.0


# This module as a value for explicit_rk.rk_step (see core/run_loop.py: modules, not dispatchers).
_THIS = sys.modules[__name__]

SPEC = Spec(
    name="nonholonomic_rk4", order=4, family="constrained", implicit=False, symplectic=False,
    symmetric=False,
    summary="rk4 on the acceleration-level KKT form of nonholonomic constraints (reference; "
            "A v + b drifts)",
    nonholonomic=True, constraint_drift="grows",
    saved=(("multipliers", "r"), ("velocity_constraint_error", 1)),
    settings=ExplicitSettings,
    kernels=("dynamics", "nonholonomic"))
