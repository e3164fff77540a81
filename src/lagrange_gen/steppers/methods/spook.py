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

solved as one system in x = (v+, nu), (n + m), by solve.newton_solve (LU with partial pivoting;
SINGULAR_NEWTON when it is singular, e.g. redundant constraints at epsilon = 0). One linear
solve per step, no Newton.

Order 1 (the discretization is symplectic-Euler-like). Properties the tests check: for fixed h
it is stable for any stiffness, including epsilon = 0 (rigid, stabilized constraints): on the
scalar constraint the step matrix of (Phi, h dPhi/dt) has determinant Upsilon < 1 and trace
1 - 3 Upsilon + O(epsilon), so rho < 1 for every d > 0 (d -> 0 is marginal, d < 0 unstable). With
epsilon = 1/k it reproduces a spring of stiffness k on Phi without the step-size limit
h omega < 2 of explicit methods; as k -> inf it converges to the rigid constraint. The
constraints are not met to a Newton tolerance: |Phi| is O(h^2) plus the spring's static
stretch epsilon |lam|, and is reported as is. Non-constraint forces are explicit (stiff springs
in V still limit h).

Settings (SpookSettings): compliance = epsilon >= 0, relaxation = d > 0 (Lacoursiere recommends
a few steps; default 2). The reported multiplier is lam = nu / h.
"""

from collections import namedtuple
from typing import NamedTuple

import numpy as np
from ...jit.cache import njit

from ..core.options import FAST, inline_step

from ..core.solve import newton_solve
from ..core.constrained import SAVED, constraint_rate, record
from ..core.method_spec import Spec
from ..core.status import OK

#: Scratch of one run (n coordinates, m constraints): the unknown x = (v+, nu) (right-hand side
#: on entry), solver scratch s and pivots (n + m), the matrix K (n + m, n + m); rhs f (n); M (n,
#: n); Phi, gamma (m); J(q), J(q+) (m, n).
Workspace = namedtuple("Workspace", "x s piv K f H phi gam G Jb")


class SpookSettings(NamedTuple):
    """spook's settings (no Newton: one linear solve per step)."""

    blowup_bound: float = 1e150
    compliance: float = 0.0      # epsilon >= 0: 1/stiffness of Phi (0: rigid)
    relaxation: float = 2.0      # d = tau / h > 0: constraint damping time in steps


@njit
def workspace(kern, n):
    """Allocated once per run by run_loop.run_loop."""
    m = kern.N_CONSTRAINTS
    N = n + m
    return Workspace(np.zeros(N), np.zeros(N), np.zeros(N, np.int64), np.zeros((N, N)),
                     np.zeros(n), np.zeros((n, n)), np.zeros(m), np.zeros(m), np.zeros((m, n)),
                     np.zeros((m, n)))


@njit(**FAST)
def prepare(kern, q, v, mom, t, p, settings, ws, extra):
    """Nothing is carried between steps."""
    return OK


@njit(inline=inline_step, **FAST)
def step(kern, q, v, mom, t, h, p, settings, ws, extra):
    """One step from (q, v) at t, in place. Returns (status, 0, 0.0): no Newton iterations."""
    n, m = q.shape[0], kern.N_CONSTRAINTS
    x, K, M, G, phi = ws.x, ws.K, ws.H, ws.G, ws.phi
    ups = 1.0 / (1.0 + 4.0 * settings.relaxation)
    sigma = 4.0 * settings.compliance * ups / (h * h)
    kern.dynamics(q, v, t, p, M, ws.f)
    kern.constraints(q, v, t, p, phi, G, ws.gam)
    constraint_rate(kern, q, t, p, ws.gam)             # gam: dPhi/dt (spook needs no gamma)
    for i in range(n):                        # [M, -G^T] x = M v + h f
        s = h * ws.f[i]
        for j in range(n):
            s += M[i, j] * v[j]
            K[i, j] = M[i, j]
        for k in range(m):
            K[i, n + k] = -G[k, i]
        x[i] = s
    for k in range(m):                        # [G, sigma I] x = -(4/h) ups Phi + ups G v
        s = -4.0 / h * ups * phi[k] + (ups - 1.0) * ws.gam[k]   # J v + dPhi/dt as velocity error
        for j in range(n):
            s += ups * G[k, j] * v[j]
            K[n + k, j] = G[k, j]
        for j in range(m):
            K[n + k, n + j] = sigma if j == k else 0.0
        x[n + k] = s
    status = newton_solve(K, ws.piv, x, ws.s)
    if status != OK:
        return status, 0, 0.0
    for i in range(n):
        v[i] = x[i]
        q[i] += h * x[i]
    for k in range(m):
        extra[k] = x[n + k] / h
    kern.constraints(q, v, t + h, p, phi, ws.Jb, ws.gam)
    constraint_rate(kern, q, t + h, p, ws.gam)
    record(extra, m, phi, ws.Jb, v, ws.gam)
    return OK, 0, 0.0


SPEC = Spec(
    name="spook", order=1, family="constrained", implicit=True, symplectic=False,
    symmetric=False,
    summary="Lacoursiere's regularized linearly implicit stepper (compliance, relaxation)",
    constraints=True,
    saved=SAVED, constraint_drift="bounded",
    limits={"compliance": (0.0, True, False), "relaxation": (0.0, False, False)},
    settings=SpookSettings,
    kernels=("constraint_rate", "constraints", "dynamics"))
