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
(CONTACT_NOT_CONVERGED: never a silent unconverged impulse). A sticking contact gets the exact
impulse that zeroes u_T: no creep.

Order 1 (impacts located to within a step). theta = 1/2 (default) is energy-neutral in free
flight; the work of the contact impulses per step is r . (W v + W v+) / 2 (the kinetic energy
change an impulse causes; the surface's own velocity b is not part of it), and for forces that do not depend on q and v
(the bouncing ball, the block on a ramp) E - E0 - W_contact = 0 to rounding at theta = 1/2.
Positions may go below the gap by O(h |u_N|) at an impact (the impulse acts on velocities);
``min_gap`` reports it. No Newton: one LU of A per step.

``extra`` (SPEC.saved), c = kern.N_CONTACTS: active contacts (1), normal impulses p_N (c),
tangential impulses p_T1 (c), p_T2 (c) (zero with one tangent), the smallest gap at the end of the step (1), the cumulated work
of the contact impulses (1). The step returns (status, sweeps, last sweep's largest change).
"""

from collections import namedtuple
from typing import NamedTuple

import numpy as np
from ...jit.cache import njit

from ..core.options import FAST, inline_step
from ..core.contact_problem import contact_row, delassus, gauss_seidel
from ..core.linalg import lu_inplace, lu_solve_inplace
from ..core.method_spec import Spec
from ..core.solve import failed_solve_status
from ..core.status import CONTACT_NOT_CONVERGED, OK

#: Scratch of one run (n coordinates, c contacts). (n,): rhs f, the free velocity vf, solver
#: scratch s and pivots piv; (n, n): H, the iteration matrix A (LU-factored in place), d rhs/dq
#: Jq, d rhs/dv Jqd; (c,): gaps g, normal velocities before the step un, active flag of each
#: contact; W_N (c, n), W_T (2c, n); coef (c, 2) = (e, mu); (3c,): impulses
#: r = (p_N, p_T1, p_T2), free local velocities uf, W v before the step um, the surface terms
#: b at t (bias) and t + h (bias_end); law (2c,) every contact UNILATERAL / COULOMB
#: (core/contact_problem.py); Y (3c, n) the rows A^-1 W^T; D (3c, 3c) the Delassus matrix.
Workspace = namedtuple("Workspace", "f vf s piv H A Jq Jqd g un WN WT coef r uf active law Y D "
                                    "um bias bias_end")


class MoreauJeanSettings(NamedTuple):
    """moreau_jean's settings (no Newton: one linear solve per step, then the contact problem)."""

    blowup_bound: float = 1e150
    theta: float = 0.5            # theta method weight in (0, 1]: 1/2 energy-neutral, 1 damping
    contact_tol: float = 1e-10    # projected Gauss-Seidel stop: max change <= tol * max|r|
    max_sweeps: int = 1000        # cap on the Gauss-Seidel sweeps per step


@njit
def workspace(kern, n):
    """Allocated once per run by run_loop.run_loop."""
    c = kern.N_CONTACTS
    return Workspace(np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n, np.int64),
                     np.zeros((n, n)), np.zeros((n, n)), np.zeros((n, n)), np.zeros((n, n)),
                     np.zeros(c), np.zeros(c), np.zeros((c, n)), np.zeros((2 * c, n)),
                     np.zeros((c, 2)), np.zeros(3 * c), np.zeros(3 * c), np.zeros(c),
                     np.zeros(2 * c, np.int64), np.zeros((3 * c, n)), np.zeros((3 * c, 3 * c)),
                     np.zeros(3 * c), np.zeros(3 * c), np.zeros(3 * c))


@njit(inline="always")
def _min_gap(g):
    """The smallest entry of g (c,) (inf for no contacts)."""
    m = np.inf
    for i in range(g.shape[0]):
        m = min(m, g[i])
    return m


@njit(**FAST)
def prepare(kern, q, v, mom, t, p, settings, ws, extra):
    """Row 0 of the saved fields: no active contact, no impulse, the initial smallest gap; the
    contact work continues from what extra holds (0 at the start of a run)."""
    c = kern.N_CONTACTS
    kern.contacts(q, t, p, ws.g, ws.WN, ws.WT, ws.coef)
    for i in range(3 * c + 1):
        extra[i] = 0.0
    extra[3 * c + 1] = _min_gap(ws.g)
    return OK


@njit(inline=inline_step, **FAST)
def step(kern, q, v, mom, t, h, p, settings, ws, extra):
    """One step from (q, v) at t, in place. Returns (status, Gauss-Seidel sweeps, last change)."""
    n, c = kern.N_COORDS, kern.N_CONTACTS
    theta = settings.theta
    f, vf, A, r, uf, active, WN, WT = ws.f, ws.vf, ws.A, ws.r, ws.uf, ws.active, ws.WN, ws.WT
    kern.dynamics(q, v, t + theta * h, p, ws.H, f)
    kern.rhs_jacobian(q, v, t + theta * h, p, ws.Jq, ws.Jqd)
    for i in range(n):
        s = h * f[i]
        for j in range(n):
            s += h * h * theta * ws.Jq[i, j] * v[j]
            A[i, j] = ws.H[i, j] - h * theta * ws.Jqd[i, j] - h * h * theta * theta * ws.Jq[i, j]
        vf[i] = s
    if not lu_inplace(A, ws.piv):
        return failed_solve_status(A), 0, 0.0
    lu_solve_inplace(A, ws.piv, vf, ws.s)
    for i in range(n):
        vf[i] += v[i]
    kern.contacts(q, t, p, ws.g, WN, WT, ws.coef)
    kern.contact_bias(q, t, p, ws.bias)
    kern.contact_bias(q, t + h, p, ws.bias_end)
    n_active = 0
    for k in range(3 * c):
        w = contact_row(k, c, WN, WT)
        um, ufk = 0.0, 0.0
        for i in range(n):
            um += w[i] * v[i]
            ufk += w[i] * vf[i]
        ws.um[k] = um
        uf[k] = ufk + ws.bias_end[k]
        r[k] = 0.0
    for a in range(c):
        un = ws.um[a] + ws.bias[a]
        ws.un[a] = un
        # the gap the step reaches without contact impulses (first order in h)
        active[a] = 1.0 if ws.g[a] + h * ((1.0 - theta) * un + theta * uf[a]) <= 0.0 else 0.0
        n_active += int(active[a])
    sweeps, change = 0, 0.0
    if n_active > 0:
        delassus(c, n, active, WN, WT, A, ws.piv, ws.s, ws.Y, ws.D)
        converged, sweeps, change = gauss_seidel(c, settings.contact_tol, settings.max_sweeps,
                                                 active, ws.law, ws.coef, ws.un, uf, ws.D, r)
        if not converged:
            return CONTACT_NOT_CONVERGED, sweeps, change
    for i in range(n):
        vi = vf[i]
        for k in range(3 * c):
            if active[k % c] != 0.0:
                vi += ws.Y[k, i] * r[k]
        q[i] += h * ((1.0 - theta) * v[i] + theta * vi)
        v[i] = vi
    work = 0.0
    for k in range(3 * c):               # r . (W v- + W v+) / 2
        if active[k % c] == 0.0:
            continue
        w = contact_row(k, c, WN, WT)
        up = 0.0
        for i in range(n):
            up += w[i] * v[i]
        work += r[k] * 0.5 * (ws.um[k] + up)
    kern.contacts(q, t + h, p, ws.g, WN, WT, ws.coef)
    extra[0] = n_active
    for k in range(3 * c):
        extra[1 + k] = r[k]
    extra[3 * c + 1] = _min_gap(ws.g)
    extra[3 * c + 2] += work
    return OK, sweeps, change


SPEC = Spec(
    name="moreau_jean", order=1, family="nonsmooth", implicit=True, symplectic=False,
    symmetric=False,
    summary="Moreau-Jean time stepping: impacts (Newton) and Coulomb friction as impulses, "
            "projected Gauss-Seidel",
    contacts=True,
    saved=(("active_contacts", 1), ("normal_impulse", "c"), ("tangent_impulse", "c"),
           ("tangent2_impulse", "c"), ("min_gap", 1), ("contact_work", 1)),
    limits={"theta": (0.0, False, False), "contact_tol": (0.0, False, False),
            "max_sweeps": (1, True, False)},
    settings=MoreauJeanSettings,
    kernels=("contacts", "contact_bias", "dynamics", "rhs_jacobian"))
