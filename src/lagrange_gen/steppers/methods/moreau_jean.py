"""Moreau-Jean time stepping for unilateral contacts with impacts and Coulomb friction.

Event-free: impacts happen inside a step, as impulses at the velocity level (Moreau 1988; Jean
1999; Acary & Brogliato, "Numerical Methods for Nonsmooth Dynamical Systems", 2008, ch. 10).
With M = H(q), f = rhs(q, v, t_theta) (= Q - h - g; t_theta = t + theta h), K = d rhs/dq,
C = d rhs/dv at the start of the step, the linearized theta method is

    A (v+ - v) = h f + h^2 theta K v + W r,        A = M - h theta C - h^2 theta^2 K
    q+ = q + h ((1 - theta) v + theta v+)

with W = [W_N^T, W_T^T] (n, 3c) the contact Jacobians at q (generated ``contacts``: gaps g,
W_N = dg/dq, W_T = d slip/d qdot, two tangent rows per contact) and r = (p_N, p_T1, p_T2) the
impulses. The local velocities are u = W v + b(t) (b: generated ``contact_bias``, what a moving
surface adds; u- takes it at t, u+ at t + h). For a model whose forces are
constant (gravity) the smooth part is exact: v+ = v + h a, q+ = q + h v + h^2 a / 2 at
theta = 1/2.

Contacts in the step: those whose gap closes at the end of the step without contact impulses,
to first order: g(q) + h ((1 - theta) u_N- + theta u_N,free) <= 0 (the index set; the free
velocity, not v alone, so that a contact at rest with g = +1e-19 after rounding stays in it
instead of leaving for a step of free fall). On them, with u = W v+ = u_free + D r, u_free = W v_free,
v_free = v + A^-1 (h f + h^2 theta K v) and the Delassus operator D = W A^-1 W^T:

    Newton's impact law:  u_N + e min(u_N-, 0) >= 0  _|_  p_N >= 0   (u_N- = W_N v + b_N(t),
                          restitution e; a contact already opening at the step's start gets
                          u_N >= 0)
    Coulomb:              |p_T| <= mu p_N, p_T = -mu p_N u_T / |u_T| when u_T != 0 (the disk of
                          (p_T1, p_T2) in 3D, the interval with one tangent)

solved by projected Gauss-Seidel (core/contact_problem.py, shared with dop853_impacts), contact
by contact:
p_N <- max(0, p_N - (u_N + e min(u_N-, 0)) / D_NN), then the tangent impulse projected onto
the interval (2D) or the disk (3D), until the largest change of a sweep is at most contact_tol max|r| or max_sweeps sweeps
and, when the sweeps do not converge, Lemke's method on the same problem's LCP
(core/contact_lcp.py; CONTACT_NO_SOLUTION when it has none, CONTACT_NOT_CONVERGED when Lemke
cycles too: never a silent unconverged impulse). A sticking contact gets the exact
impulse that zeroes u_T: no creep.

Holonomic constraints Phi(q) = 0 (m rows, J = dPhi/dq) join the step as rigid equality rows of
the same linear system, K [v+ - v; nu] = [h f + h^2 theta K v + W r; target] with
K = [[A, -J^T], [J, 0]] and the target J v+ + dPhi/dt = -Phi(q) / h: the velocity constraint
with the drift Phi of the step's start removed over the step (the linearized Phi(q+) then
follows x+ = (1 - theta) x + (1 - theta) y, y+ = -x for x = Phi, y = h J v: spectral radius
sqrt(1 - theta) < 1, so |Phi| stays O(h^2), reported as constraint_error). The contacts then
act on the constrained motion: D = W K^-1 W^T (core/contact_kkt.py), and the constraint
impulses follow the contact impulses exactly. The multipliers saved are lam = nu / h.

Nonholonomic constraints A(q, t) v + b(q, t) = 0 (r rows, forces A^T mu; a wheel rolling on the
floor) join the same system as r more rigid rows after the holonomic ones, with A and b at
(q, t + h) and the target A v+ + b = 0: the step's end velocity satisfies them exactly for the
step's configuration (as W and the contact rows, A is not updated within the step), so
|A v + b| at the next configuration is O(h) times the speed of A's change and does not grow
(reported as nonholonomic_error). Contacts then act on the motion both kinds of rows allow.

Order 1 (impacts located to within a step). theta = 1/2 (default) is energy-neutral in free
flight; the work of the contact impulses per step is r . (W v + W v+) / 2 (the kinetic energy
change an impulse causes; the surface's own velocity b is not part of it), and for forces that do not depend on q and v
(the bouncing ball, the block on a ramp) E - E0 - W_contact = 0 to rounding at theta = 1/2.
Positions may go below the gap by O(h |u_N|) at an impact (the impulse acts on velocities);
``min_gap`` reports it. No Newton: one LU of K per step.

``extra`` (SPEC.saved, core/contact_kkt.CONTACT_SAVED), c = kern.N_CONTACTS: active contacts
(1), normal impulses p_N (c), tangential impulses p_T1 (c), p_T2 (c) (zero with one tangent),
the smallest gap at the end of the step (1), the cumulated work of the contact impulses (1);
with holonomic constraints the multipliers (m), max|Phi| and max|J v + dPhi/dt| at the end of
the step; with nonholonomic constraints, between the contact fields and the holonomic ones,
their multipliers (r) and max|A v + b| at the end of the step
(core/contact_kkt.NONHOLONOMIC_CONTACT_SAVED). The step returns (status, sweeps, last sweep's
largest change).
"""

from collections import namedtuple
from typing import NamedTuple

import numpy as np
from ...jit.cache import njit

from ..core.options import FAST, inline_step
from ..core.constrained import constraint_rate
from ..core.contact_kkt import (NONHOLONOMIC_CONTACT_SAVED, apply_impulses, assemble_constraint_rows,
                                contact_prepare, impulse_work, pad_rows,
                                record_constraints, record_contacts, row_dot, solve_contacts)
from ..core.contact_lcp import lcp_arrays
from ..core.linalg import lu_inplace, lu_solve_inplace
from ..core.method_spec import Spec
from ..core.solve import failed_solve_status
from ..core.status import OK

#: Scratch of one run (n coordinates, m constraints, r nonholonomic constraints, c contacts,
#: N = n + m + r, R = 3c rows). x the unknown (v+ - v, nu, mu), then (v+, nu, mu) (N,); solver
#: scratch s and pivots piv (N,); the iteration matrix K (N, N) (LU-factored in place); (n,):
#: rhs f; (n, n): H, d rhs/dq Jq, d rhs/dv Jqd; phi, gam (m,), G (m, n); the equality rows
#: E (m + r, n) (G, then A); A (r, n), b and its gamma nb, ng (r,); (c,): gaps g, relative normal velocities before the
#: step un, active flag of each contact; W_N (c, n), W_T (2c, n) and their copies padded to N
#: columns WNp, WTp; coef (c, 2) = (e, mu); (R,): impulses r = (p_N, p_T1, p_T2), free local
#: velocities uf, law (every contact UNILATERAL / COULOMB, core/contact_problem.py), the surface
#: terms b at t (bias) and t + h (bias_end); Y (R, N) the rows K^-1 [W^T; 0]; D (R, R) the
#: Delassus matrix; lcp_B, lcp_C, lcp_T, lcp_z, lcp_basis the exact fallback's scratch
#: (core/contact_lcp.lcp_arrays).
Workspace = namedtuple("Workspace",
                       "x s piv K f H Jq Jqd phi gam G E A nb ng g un active WN WT WNp WTp coef r "
                       "uf law Y D bias bias_end lcp_B lcp_C lcp_T lcp_z lcp_basis")


class MoreauJeanSettings(NamedTuple):
    """moreau_jean's settings (no Newton: one linear solve per step, then the contact problem)."""

    blowup_bound: float = 1e150
    theta: float = 0.5            # theta method weight in (0, 1]: 1/2 energy-neutral, 1 damping
    contact_tol: float = 1e-10    # projected Gauss-Seidel stop: max change <= tol * max|r|
    max_sweeps: int = 1000        # cap on the Gauss-Seidel sweeps per step


@njit
def workspace(kern, n):
    """Allocated once per run by run_loop.run_loop."""
    m, c, nr = kern.N_CONSTRAINTS, kern.N_CONTACTS, kern.N_NONHOLONOMIC
    N, T = n + m + nr, 2 * c          # T: the rows of W_T, two tangents per contact
    R = c + T
    return Workspace(np.zeros(N), np.zeros(N), np.zeros(N, np.int64), np.zeros((N, N)),
                     np.zeros(n), np.zeros((n, n)), np.zeros((n, n)), np.zeros((n, n)),
                     np.zeros(m), np.zeros(m), np.zeros((m, n)), np.zeros((m + nr, n)),
                     np.zeros((nr, n)), np.zeros(nr), np.zeros(nr), np.zeros(c), np.zeros(c),
                     np.zeros(c), np.zeros((c, n)), np.zeros((T, n)), np.zeros((c, N)),
                     np.zeros((T, N)), np.zeros((c, 2)), np.zeros(R), np.zeros(R),
                     np.zeros(R, np.int64), np.zeros((R, N)), np.zeros((R, R)), np.zeros(R),
                     np.zeros(R), *lcp_arrays(c))


#: Row 0 of the saved fields (core/contact_kkt.py), shared with the other contact method.
prepare = contact_prepare


@njit(inline=inline_step, **FAST)
def step(kern, q, v, mom, t, h, p, settings, ws, extra):
    """One step from (q, v) at t, in place. Returns (status, Gauss-Seidel sweeps, last change)."""
    n, m, c, nr = kern.N_COORDS, kern.N_CONSTRAINTS, kern.N_CONTACTS, kern.N_NONHOLONOMIC
    N, R = n + m + nr, ws.r.shape[0]
    theta = settings.theta
    x, K, G, phi, gam, WN, WT, E, A = ws.x, ws.K, ws.G, ws.phi, ws.gam, ws.WN, ws.WT, ws.E, ws.A
    kern.dynamics(q, v, t + theta * h, p, ws.H, ws.f)
    kern.rhs_jacobian(q, v, t + theta * h, p, ws.Jq, ws.Jqd)
    for i in range(n):
        s = h * ws.f[i]
        for j in range(n):
            s += h * h * theta * ws.Jq[i, j] * v[j]
            K[i, j] = ws.H[i, j] - h * theta * ws.Jqd[i, j] - h * h * theta * theta * ws.Jq[i, j]
        x[i] = s
    kern.constraints(q, v, t, p, phi, G, gam)
    constraint_rate(kern, q, t, p, gam)                # gam: dPhi/dt
    kern.nonholonomic(q, v, t + h, p, A, ws.nb, ws.ng)
    for k in range(m):                                 # G (v+ - v) = -Phi / h - dPhi/dt - G v
        s = -phi[k] / h - gam[k]
        for j in range(n):
            E[k, j] = G[k, j]
            s -= G[k, j] * v[j]
        x[n + k] = s
    for k in range(nr):                                # A (v+ - v) = -b - A v
        s = -ws.nb[k]
        for j in range(n):
            E[m + k, j] = A[k, j]
            s -= A[k, j] * v[j]
        x[n + m + k] = s
    assemble_constraint_rows(K, n, E, 0.0)
    if not lu_inplace(K, ws.piv):
        return failed_solve_status(K), 0, 0.0
    lu_solve_inplace(K, ws.piv, x, ws.s)
    for i in range(n):
        x[i] += v[i]                                   # x = (v_free, nu_free)
    kern.contacts(q, t, p, ws.g, WN, WT, ws.coef)
    kern.contact_bias(q, t, p, ws.bias)
    kern.contact_bias(q, t + h, p, ws.bias_end)
    pad_rows(n, WN, WT, ws.WNp, ws.WTp)
    n_active = 0
    for a in range(c):
        un = row_dot(a, c, WN, WT, v, n) + ws.bias[a]
        ufn = row_dot(a, c, WN, WT, x, n) + ws.bias_end[a]
        ws.un[a] = un
        ws.uf[a] = ufn
        # the gap the step reaches without contact impulses (first order in h)
        ws.active[a] = 1.0 if ws.g[a] + h * ((1.0 - theta) * un + theta * ufn) <= 0.0 else 0.0
        n_active += int(ws.active[a])
    for k in range(c, R):
        ws.uf[k] = row_dot(k, c, WN, WT, x, n) + ws.bias_end[k]
    for k in range(R):
        ws.r[k] = 0.0
    sweeps, change = 0, 0.0
    if n_active > 0:
        status, sweeps, change = solve_contacts(
            c, N, settings.contact_tol, settings.max_sweeps, ws.active, ws.law, ws.coef, ws.un,
            ws.uf, ws.WNp, ws.WTp, K, ws.piv, ws.s, ws.Y, ws.D, 0.0, ws.r,
            (ws.lcp_B, ws.lcp_C, ws.lcp_T, ws.lcp_z, ws.lcp_basis))
        if status != OK:
            return status, sweeps, change
        apply_impulses(c, ws.active, ws.Y, ws.r, x)
    work = impulse_work(c, n, WN, WT, v, x, ws.r)
    for i in range(n):
        q[i] += h * ((1.0 - theta) * v[i] + theta * x[i])
        v[i] = x[i]
    kern.contacts(q, t + h, p, ws.g, WN, WT, ws.coef)
    record_contacts(extra, n_active, ws.r, ws.g, work)
    kern.nonholonomic(q, v, t + h, p, A, ws.nb, ws.ng)
    record_nonholonomic(extra, R + 3, x, n + m, 1.0 / h, A, ws.nb, v)
    kern.constraints(q, v, t + h, p, phi, G, gam)
    constraint_rate(kern, q, t + h, p, gam)
    record_constraints(extra, R + 3 + nr + min(nr, 1), x, n, 1.0 / h, phi, G, v, gam)
    return OK, sweeps, change


@njit(inline="always")
def record_nonholonomic(extra, start, x, at, scale, A, b, v):
    """The nonholonomic fields of extra from index start (nothing without them): the
    multipliers x[at + k] * scale (r), then max|A v + b| (A (r, n), b (r,) at the end of the
    step)."""
    nr = b.shape[0]
    if nr == 0:
        return
    worst = 0.0
    for k in range(nr):
        extra[start + k] = x[at + k] * scale
        s = b[k]
        for j in range(v.shape[0]):
            s += A[k, j] * v[j]
        if abs(s) > worst or s != s:
            worst = abs(s)
    extra[start + nr] = worst


SPEC = Spec(
    name="moreau_jean", order=1, family="nonsmooth", implicit=True, symplectic=False,
    symmetric=False,
    summary="Moreau-Jean time stepping: impacts (Newton) and Coulomb friction as impulses, "
            "projected Gauss-Seidel",
    contacts=True, holonomic_too=True, nonholonomic_too=True, constraint_drift="bounded",
    saved=NONHOLONOMIC_CONTACT_SAVED,
    limits={"theta": (0.0, False, False), "contact_tol": (0.0, False, False),
            "max_sweeps": (1, True, False)},
    settings=MoreauJeanSettings,
    kernels=("constraint_rate", "constraints", "contact_bias", "contacts", "dynamics",
             "nonholonomic", "rhs_jacobian"))
