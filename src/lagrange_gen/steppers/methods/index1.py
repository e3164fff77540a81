"""Index-1 (acceleration-level) formulation integrated by rk4: the documented bad example.

The constraint Phi(q) = 0 is replaced by its second derivative J qdd = gamma (generated
``constraints``: gamma = -(dJ/dt) v), optionally with Baumgarte's stabilization
Phi'' + 2 alpha Phi' + beta^2 Phi = 0, and the accelerations come from the KKT system

    [[H, -J^T], [J, 0]] (a, lam) = (rhs, gamma - 2 alpha J v - beta^2 Phi)

(solved through the Schur complement J H^-1 J^T, Cholesky). The resulting ODE in (q, v) is
integrated by the classical rk4 (order 4; explicit_rk's core with the rk4 tableau), which is
what a user of scipy's solve_ivp or of sympy.physics.mechanics / PyDy does.

Why it is bad (Lacoursiere's slides; Hairer-Wanner II, sec. VII.2): Phi'' = 0 holds along the
numerical solution only up to the local error, so Phi and J v are not controlled at all: the
errors in J v integrate to a drift of Phi that grows with t (linearly in J v, quadratically in
Phi for a constant error source) and nothing pulls the motion back onto the manifold. Baumgarte's
terms turn the drift into a damped oscillation around Phi = 0 for alpha, beta > 0, but bias the
dynamics and need alpha, beta tuned to h. The tests and bench show |Phi| growing over 1e5 steps
while the projected methods stay at the Newton tolerance. The multiplier and the residuals are
reported at the end of every step (the acceleration there is cached for the next step's first
stage: four KKT solves per step; prepare computes the first one).

Settings (Index1Settings): baumgarte = (alpha, beta) (default (0, 0): no stabilization).
"""

import sys
from collections import namedtuple
from typing import NamedTuple

import numpy as np
from ...jit.cache import njit

from ..core.options import FAST, inline_step
from ..core.constrained import SAVED, constraint_rate, record, solve_rows
from ..core.explicit_rk import RK4_A, RK4_B, RK4_C, rk_step
from ..core.linalg import cholesky_inplace, cholesky_solve_inplace
from ..core.method_spec import Spec
from ..core.status import OK, SINGULAR_MASS

#: Scratch of one run (n coordinates, m constraints): the acceleration a0 at the current state
#: (cached from step to step), stage velocities and accelerations (4, n), stage q qs, the new
#: state (n); H (n, n); stage multipliers ls, Phi, gamma (m); J, H^-1 J^T rows Y (m, n); Schur
#: S (m, m).
Workspace = namedtuple("Workspace", "a0 stage_v stage_a qs q_new v_new H ls phi gam J Y S")


class Index1Settings(NamedTuple):
    """index1's settings: Baumgarte's (alpha, beta), Phi'' + 2 alpha Phi' + beta^2 Phi = 0."""

    blowup_bound: float = 1e150
    baumgarte: tuple = (0.0, 0.0)


@njit
def workspace(kern, n):
    """Allocated once per run by run_loop.run_loop."""
    m = kern.N_CONSTRAINTS
    return Workspace(np.zeros(n), np.zeros((4, n)), np.zeros((4, n)), np.zeros(n), np.zeros(n),
                     np.zeros(n), np.zeros((n, n)), np.zeros(m), np.zeros(m), np.zeros(m),
                     np.zeros((m, n)), np.zeros((m, n)), np.zeros((m, m)))


@njit(**FAST)
def _accel(kern, q, v, t, p, alpha, beta, H, a, lam, phi, J, gam, Y, S):
    """a (n,) and lam (m,) from the KKT system at (q, v, t); phi, J, gam (the constraint
    kernel's outputs at q) stay available to the caller. Status OK or SINGULAR_MASS."""
    n, m = q.shape[0], phi.shape[0]
    kern.dynamics(q, v, t, p, H, a)
    kern.constraints(q, v, t, p, phi, J, gam)
    constraint_rate(kern, q, t, p, lam)       # lam holds dPhi/dt until overwritten below
    if not cholesky_inplace(H):
        return SINGULAR_MASS
    cholesky_solve_inplace(H, a)              # unconstrained acceleration
    solve_rows(H, J, Y)
    for i in range(m):
        s = gam[i] - beta * beta * phi[i] - 2.0 * alpha * lam[i]
        for j in range(n):
            s -= J[i, j] * (2.0 * alpha * v[j] + a[j])
        lam[i] = s
        for k in range(m):
            s = 0.0
            for j in range(n):
                s += J[i, j] * Y[k, j]
            S[i, k] = s
    if not cholesky_inplace(S):
        return SINGULAR_MASS
    cholesky_solve_inplace(S, lam)
    for k in range(m):
        for j in range(n):
            a[j] += Y[k, j] * lam[k]
    return OK


@njit(**FAST)
def prepare(kern, q, v, mom, t, p, settings, ws, extra):
    """The acceleration at the initial state (the first stage of the first step); the saved
    multiplier of row 0 (from the driver) is left as it is."""
    alpha, beta = settings.baumgarte
    return _accel(kern, q, v, t, p, alpha, beta, ws.H, ws.a0, ws.ls, ws.phi, ws.J, ws.gam,
                  ws.Y, ws.S)


@njit(**FAST)
def stage_acceleration(kern, ctx, q, v, t, a):
    """explicit_rk's callback: a (n,) from the KKT system (_accel); the stage multipliers go to
    scratch. ctx = (p, alpha, beta, ws)."""
    p, alpha, beta, ws = ctx
    return _accel(kern, q, v, t, p, alpha, beta, ws.H, a, ws.ls, ws.phi, ws.J, ws.gam, ws.Y,
                  ws.S)


@njit(inline=inline_step, **FAST)
def step(kern, q, v, mom, t, h, p, settings, ws, extra):
    """One rk4 step from (q, v) at t, in place. Returns (status, 0, 0.0)."""
    n, m = q.shape[0], kern.N_CONSTRAINTS
    alpha, beta = settings.baumgarte
    a0, stage_a, q_new, v_new = ws.a0, ws.stage_a, ws.q_new, ws.v_new
    for i in range(n):
        stage_a[0, i] = a0[i]
    status = rk_step(_THIS, kern, (p, alpha, beta, ws), RK4_A, RK4_B, RK4_C, q, v, t, h,
                     ws.stage_v, stage_a, ws.qs, q_new, v_new, True)
    if status != OK:
        return status, 0, 0.0
    # Acceleration and multiplier at the new state: reported now, first stage of the next step.
    status = _accel(kern, q_new, v_new, t + h, p, alpha, beta, ws.H, stage_a[0], ws.ls, ws.phi,
                    ws.J, ws.gam, ws.Y, ws.S)
    if status != OK:
        return status, 0, 0.0
    for i in range(n):
        q[i], v[i], a0[i] = q_new[i], v_new[i], stage_a[0, i]
    for k in range(m):
        extra[k] = ws.ls[k]
    constraint_rate(kern, q, t + h, p, ws.gam)
    record(extra, m, ws.phi, ws.J, v, ws.gam)
    return OK, 0, 0.0


# This module as a value for explicit_rk.rk_step (see core/run_loop.py: modules, not dispatchers).
_THIS = sys.modules[__name__]

SPEC = Spec(
    name="index1", order=4, family="constrained", implicit=False, symplectic=False,
    symmetric=False,
    summary="rk4 on the acceleration-level KKT form (drifts: the bad example)",
    constraints=True,
    saved=SAVED, constraint_drift="grows",
    limits={"baumgarte": (0.0, True, False)},
    settings=Index1Settings,
    kernels=("constraint_rate", "constraints", "dynamics"))
