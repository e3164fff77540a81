"""SPOOK with unilateral contacts: Lacoursiere's regularized, stabilized, linearly implicit step
(methods/spook.py) with the contacts as regularized unilateral rows and Coulomb friction as
multipliers bounded by mu times the normal one, and the model's holonomic constraints (if any)
as regularized equality rows.

With M = H(q), f = rhs(q, v, t), G = J(q), Phi = Phi(q) at the start of the step, the
equality rows are spook's (its docstring):

    K [v+; nu] = [M v + h f; -(4/h) Upsilon Phi + Upsilon G v + (Upsilon - 1) dPhi/dt]
    K = [[M, -G^T], [G, Sigma I]],   Sigma = 4 epsilon / (h^2 (1 + 4 d)),   Upsilon = 1 / (1 + 4 d)

and the contact impulses r = (p_N, p_T1, p_T2) add [W^T r; 0] to the right-hand side,
q+ = q + h v+.
The contacts in the step are those whose gap the step reaches without contact impulses is
closed, g + h u_N,free <= 0 (as in moreau_jean). On them, with u+ = W v+ + b(t + h)
(= u_free + D r, D = W K^-1 W^T the Delassus operator of the constrained motion,
core/contact_kkt.py; b the generated ``contact_bias``, what a moving surface adds):

    normal:   u_N+ + Sigma p_N + b  >= 0  _|_  p_N >= 0,
              b = min((4/h) Upsilon g - Upsilon u_N-,  e min(u_N-, 0))
    friction: u_T+ + Sigma p_T = 0 where |p_T| < mu p_N, else on the bound |p_T| = mu p_N
              opposing the slip (the interval with one tangent, the disk with two)

with u_N- = W_N v + b_N(t). The first term of b is spook's regularized, stabilized row of the gap (the
spring-damper limit: a penetration decays over about d steps instead of being removed in one,
and with compliance epsilon > 0 the contact is a spring of stiffness 1/epsilon); the second is
Newton's impact law on the approaching velocity (restitution e): the row takes whichever of
the two asks for the larger separating velocity, so an impact leaves with -e u_N- and a
resting contact is held by the stabilization alone. Solved by projected Gauss-Seidel on the
regularized Delassus matrix D + Sigma I (core/contact_problem.py), with moreau_jean's stopping
rule and its fallback (Lemke's method when max_sweeps pass, core/contact_lcp.py).

Order 1. Resting contact is stable for any h (the stabilized row has spook's step matrix, the
spectral radius below 1 for every d > 0): a box or a stack at rest stays at rest with a
penetration of the order of the static spring stretch epsilon |lam| plus rounding. A falling
body hitting the floor penetrates by O(h |u_N|) in its impact step at most. The contact work
per step is r . (u- + u+) / 2 (u- = W v, u+ = W v+); free flight is spook's symplectic-Euler-
like step, whose energy oscillates by O(h) without drift (for gravity alone E - h m g v / 2 is
kept exactly), so E - E0 - W_contact is O(h), not rounding as for moreau_jean at theta = 1/2.

``extra`` (SPEC.saved, core/contact_kkt.CONTACT_SAVED): active contacts (1), normal and tangent
impulses, the smallest gap at the end of the step (1), the cumulated contact work (1); with
holonomic constraints the multipliers lam = nu / h (m), max|Phi| and max|J v + dPhi/dt| at the
end of the step. The step returns (status, Gauss-Seidel sweeps, last sweep's largest change).

Settings: compliance = epsilon >= 0 and relaxation = d > 0 for every row (equality and contact),
contact_tol and max_sweeps for the projected Gauss-Seidel.
"""

from collections import namedtuple
from typing import NamedTuple

import numpy as np
from ...jit.cache import njit

from ..core.options import FAST, inline_step
from ..core.constrained import constraint_rate
from ..core.contact_kkt import (CONTACT_SAVED, apply_impulses, assemble_constraint_rows,
                                contact_prepare, impulse_work, pad_rows,
                                record_constraints, record_contacts, row_dot, solve_contacts)
from ..core.contact_lcp import lcp_arrays
from ..core.linalg import lu_inplace, lu_solve_inplace
from ..core.method_spec import Spec
from ..core.solve import failed_solve_status
from ..core.status import OK

#: Scratch of one run (n coordinates, m constraints, c contacts, N = n + m, R = n_rows): x the
#: unknown (v+, nu) (N,); xs solver scratch (N,); piv (N,); K (N, N); f rhs (n,); H (n, n);
#: phi, gam (m,); G (m, n); g gaps (c,); WN (c, n), WT (R - c, n) and their padded copies WNp,
#: WTp (N columns); coef (c, 2) = (e, mu); zero (c,) (Newton's law is folded into uf, so the
#: solver's approach velocities are zeros); (R,): impulses r, free local velocities uf, law
#: (every row UNILATERAL / COULOMB), the surface terms b at t (bias) and t + h (bias_end);
#: active (c,); Y (R, N); D (R, R); lcp_B, lcp_C, lcp_T, lcp_z, lcp_basis the exact fallback's
#: scratch (core/contact_lcp.lcp_arrays).
Workspace = namedtuple("Workspace",
                       "x xs piv K f H phi gam G g WN WT WNp WTp coef zero r uf law active Y D "
                       "bias bias_end lcp_B lcp_C lcp_T lcp_z lcp_basis")


class SpookContactSettings(NamedTuple):
    """spook_contacts' settings (one linear solve per step, then the contact problem)."""

    blowup_bound: float = 1e150
    compliance: float = 0.0       # epsilon >= 0 of every row (0: rigid)
    relaxation: float = 2.0       # d = tau / h > 0: the rows' relaxation time in steps
    contact_tol: float = 1e-10    # projected Gauss-Seidel stop: max change <= tol * max|r|
    max_sweeps: int = 1000        # cap on the Gauss-Seidel sweeps per step


@njit
def workspace(kern, n):
    """Allocated once per run by run_loop.run_loop."""
    m, c = kern.N_CONSTRAINTS, kern.N_CONTACTS
    N, T = n + m, 2 * c               # T: the rows of W_T, two tangents per contact
    R = c + T
    return Workspace(np.zeros(N), np.zeros(N), np.zeros(N, np.int64), np.zeros((N, N)),
                     np.zeros(n), np.zeros((n, n)), np.zeros(m), np.zeros(m),
                     np.zeros((m, n)), np.zeros(c), np.zeros((c, n)), np.zeros((T, n)),
                     np.zeros((c, N)), np.zeros((T, N)), np.zeros((c, 2)), np.zeros(c),
                     np.zeros(R), np.zeros(R), np.zeros(R, np.int64), np.zeros(c),
                     np.zeros((R, N)), np.zeros((R, R)), np.zeros(R), np.zeros(R),
                     *lcp_arrays(c))


#: Row 0 of the saved fields (core/contact_kkt.py), shared with the other contact method.
prepare = contact_prepare


@njit(inline=inline_step, **FAST)
def step(kern, q, v, mom, t, h, p, settings, ws, extra):
    """One step from (q, v) at t, in place. Returns (status, Gauss-Seidel sweeps, last change)."""
    n, m, c = kern.N_COORDS, kern.N_CONSTRAINTS, kern.N_CONTACTS
    N, R = n + m, ws.r.shape[0]
    x, K, M, G, phi, gam = ws.x, ws.K, ws.H, ws.G, ws.phi, ws.gam
    ups = 1.0 / (1.0 + 4.0 * settings.relaxation)
    sigma = 4.0 * settings.compliance * ups / (h * h)
    kern.dynamics(q, v, t, p, M, ws.f)
    kern.constraints(q, v, t, p, phi, G, gam)
    constraint_rate(kern, q, t, p, gam)                # gam: dPhi/dt
    for i in range(n):                                 # [M, -G^T] x = M v + h f
        s = h * ws.f[i]
        for j in range(n):
            s += M[i, j] * v[j]
            K[i, j] = M[i, j]
        x[i] = s
    assemble_constraint_rows(K, n, G, sigma)
    for k in range(m):                                 # [G, Sigma I] x = spook's row
        s = -4.0 / h * ups * phi[k] + (ups - 1.0) * gam[k]
        for j in range(n):
            s += ups * G[k, j] * v[j]
        x[n + k] = s
    if not lu_inplace(K, ws.piv):
        return failed_solve_status(K), 0, 0.0
    lu_solve_inplace(K, ws.piv, x, ws.xs)              # x = (v_free, nu_free)
    kern.contacts(q, t, p, ws.g, ws.WN, ws.WT, ws.coef)
    kern.contact_bias(q, t, p, ws.bias)
    kern.contact_bias(q, t + h, p, ws.bias_end)
    pad_rows(n, ws.WN, ws.WT, ws.WNp, ws.WTp)
    n_active = 0
    for a in range(c):
        un = row_dot(a, c, ws.WN, ws.WT, v, n) + ws.bias[a]
        ufn = row_dot(a, c, ws.WN, ws.WT, x, n) + ws.bias_end[a]
        ws.active[a] = 1.0 if ws.g[a] + h * ufn <= 0.0 else 0.0
        n_active += int(ws.active[a])
        stabilized = 4.0 / h * ups * ws.g[a] - ups * un
        ws.uf[a] = ufn + min(stabilized, ws.coef[a, 0] * min(un, 0.0))
    for k in range(c, R):
        ws.uf[k] = row_dot(k, c, ws.WN, ws.WT, x, n) + ws.bias_end[k]
    for k in range(R):
        ws.r[k] = 0.0
    sweeps, change = 0, 0.0
    if n_active > 0:
        status, sweeps, change = solve_contacts(
            c, N, settings.contact_tol, settings.max_sweeps, ws.active, ws.law, ws.coef, ws.zero,
            ws.uf, ws.WNp, ws.WTp, K, ws.piv, ws.xs, ws.Y, ws.D, sigma, ws.r,
            (ws.lcp_B, ws.lcp_C, ws.lcp_T, ws.lcp_z, ws.lcp_basis))
        if status != OK:
            return status, sweeps, change
        apply_impulses(c, ws.active, ws.Y, ws.r, x)
    work = impulse_work(c, n, ws.WN, ws.WT, v, x, ws.r)
    for i in range(n):
        v[i] = x[i]
        q[i] += h * x[i]
    kern.contacts(q, t + h, p, ws.g, ws.WN, ws.WT, ws.coef)
    record_contacts(extra, n_active, ws.r, ws.g, work)
    kern.constraints(q, v, t + h, p, phi, G, gam)
    constraint_rate(kern, q, t + h, p, gam)
    record_constraints(extra, R + 3, x, n, 1.0 / h, phi, G, v, gam)
    return OK, sweeps, change


SPEC = Spec(
    name="spook_contacts", order=1, family="nonsmooth", implicit=True, symplectic=False,
    symmetric=False,
    summary="SPOOK with contacts: regularized, stabilized unilateral rows (Newton restitution), "
            "Coulomb friction bounded by mu p_N, projected Gauss-Seidel; holonomic constraints too",
    contacts=True, holonomic_too=True, constraint_drift="bounded",
    saved=CONTACT_SAVED,
    limits={"compliance": (0.0, True, False), "relaxation": (0.0, False, False),
            "contact_tol": (0.0, False, False), "max_sweeps": (1, True, False)},
    settings=SpookContactSettings,
    kernels=("constraint_rate", "constraints", "contact_bias", "contacts", "dynamics"))
