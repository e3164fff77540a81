"""SPOOK: Lacoursiere's regularized, stabilized, linearly implicit stepper for constraints.

A constraint is treated as the limit of a stiff spring-damper: potential Phi^T Phi / (2 epsilon)
(compliance epsilon = 1/stiffness of Phi) and Rayleigh dissipation with relaxation time
tau = d h, i.e. the force J^T lam with epsilon lam + Phi + tau dPhi/dt = 0. Discretized as in
Lacoursiere (Ghosts and Machines, Umea 2007; "Regularized, stabilized, variational methods for
multibodies", 2007), with M = H(q), f = rhs(q, v, t) (= Q - h - g), G = J(q), Phi = Phi(q) at the
start of the step and nu = h lam the impulse:

    [[M,  -G^T    ], [v+]   [M v + h f                   ]
     [G,  Sigma I ]] [nu] = [-(4/h) Upsilon Phi + Upsilon G v]

    Sigma = 4 epsilon / (h^2 (1 + 4 d)),   Upsilon = 1 / (1 + 4 d),   q+ = q + h v+

solved through the SPD Schur complement (G M^-1 G^T + Sigma I) nu = rhs (Cholesky; M factored
once per step). One linear solve per step, no Newton.

Order 1 (the discretization is symplectic-Euler-like). Properties the tests check: for fixed h
it is stable for any stiffness, including epsilon = 0 (rigid, stabilized constraints): on the
scalar constraint the step matrix of (Phi, h dPhi/dt) has determinant Upsilon < 1 and trace
1 - 3 Upsilon + O(epsilon), so rho < 1 for every d > 0 (d -> 0 is marginal, d < 0 unstable). With
epsilon = 1/k it reproduces a spring of stiffness k on Phi without the step-size limit
h omega < 2 of explicit methods; as k -> inf it converges to the rigid constraint. The
constraints are not met to a Newton tolerance: |Phi| is O(h^2) plus the spring's static
stretch epsilon |lam|, and is reported as is. Non-constraint forces are explicit (stiff springs
in V still limit h).

Settings: settings[S_COMPLIANCE] = epsilon >= 0, settings[S_RELAXATION] = d > 0 (Lacoursiere
recommends a few steps; default 2). The reported multiplier is lam = nu / h.
"""

import sys
from typing import NamedTuple

from numba import njit

from ..linalg import cholesky_inplace, cholesky_solve_inplace
from ..status import OK, SINGULAR_MASS
from .spec import Spec
from .base import FAST, run_loop
from .constrained import (S_COMPLIANCE, S_RELAXATION, check_buffers, record, schur_block,
                          solve_rows, views)

_VF, _Q1, _V1, _F = 0, 1, 2, 3     # work rows
_H = 0                             # mats


@njit(**FAST)
def prepare(kern, q, v, mom, t, p, settings, work, mats, piv):
    """Nothing is carried between steps."""
    return OK


@njit(**FAST)
def step(kern, q, v, mom, t, h, p, settings, work, mats, piv, extra):
    """One step from (q, v) at t, in place. Returns (status, 0, 0.0): no Newton iterations."""
    n, m = q.shape[0], kern.N_CONSTRAINTS
    eps, d = settings[S_COMPLIANCE], settings[S_RELAXATION]
    vf, q1, v1, f = work[_VF], work[_Q1], work[_V1], work[_F]
    H = mats[_H]
    lam, phi, gam, r, c2, c3, G, Jb, Y, T, b, K = views(extra, n, m, m)
    S = schur_block(extra, n, m)
    ups = 1.0 / (1.0 + 4.0 * d)
    sigma = 4.0 * eps * ups / (h * h)
    kern.dynamics(q, v, t, p, H, f)
    kern.constraints(q, v, p, phi, G, gam)
    if not cholesky_inplace(H):
        return SINGULAR_MASS, 0, 0.0
    cholesky_solve_inplace(H, f)
    for i in range(n):
        vf[i] = v[i] + h * f[i]               # unconstrained velocity
    solve_rows(H, G, Y)                       # rows M^-1 G_k^T
    for i in range(m):
        s = -4.0 / h * ups * phi[i]
        for j in range(n):
            s += ups * G[i, j] * v[j] - G[i, j] * vf[j]
        r[i] = s
        for k in range(m):
            s = 0.0
            for j in range(n):
                s += G[i, j] * Y[k, j]
            S[i, k] = s
        S[i, i] += sigma
    if not cholesky_inplace(S):
        return SINGULAR_MASS, 0, 0.0
    cholesky_solve_inplace(S, r)              # r = nu
    for i in range(n):
        s = vf[i]
        for k in range(m):
            s += Y[k, i] * r[k]
        v1[i] = s
        q1[i] = q[i] + h * s
    for i in range(n):
        q[i], v[i] = q1[i], v1[i]
    for k in range(m):
        lam[k] = r[k] / h
    kern.constraints(q, v, p, phi, Jb, gam)
    record(extra, m, phi, Jb, v)
    return OK, 0, 0.0


@njit(inline="always")
def run(kern, q0, v0, t0, h, n_steps, save_every, p, settings,
        out_t, out_q, out_v, out_stats, out_extra, out_last):
    """See base.run_loop and constrained.py: out_extra (S, m + 2), out_last (2n + 3 + total)
    with (m + 2, total) = constrained.extra_size(n, m), settings (N_CONSTRAINED_SETTINGS,)."""
    check_buffers(kern, q0, settings, out_extra, out_last)
    return run_loop(_THIS, kern, q0, v0, t0, h, n_steps, save_every, p, settings,
                    out_t, out_q, out_v, out_stats, out_extra, out_last)


# This module as a value for run_loop (see base.py: modules, not dispatchers, are passed).
_THIS = sys.modules[__name__]

class SpookSettings(NamedTuple):
    """spook's settings (no Newton: one linear solve per step)."""

    blowup_bound: float = 1e150
    compliance: float = 0.0      # epsilon >= 0: 1/stiffness of Phi (0: rigid)
    relaxation: float = 2.0      # d = tau / h > 0: constraint damping time in steps


SPEC = Spec(
    name="spook", order=1, family="constrained", implicit=True, symplectic=False,
    symmetric=False,
    summary="Lacoursiere's regularized linearly implicit stepper (compliance, relaxation)",
    constraints=True,
    saved=(("multipliers", "m"), ("constraint_error", 1), ("velocity_constraint_error", 1)),
    limits={"compliance": (0.0, True, False), "relaxation": (0.0, False, False)},
    settings=SpookSettings,
    kernels=("constraints", "dynamics", "energy"))
