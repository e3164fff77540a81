"""The contact problem of a time step whose free motion also carries holonomic constraints.

A contact stepper (moreau_jean, spook_contacts) writes its step as one linear system in
x = (velocity unknown (n), constraint impulses nu (m)), N = n + m:

    K x = b,    K = [[A, -G^T], [G, S]]    (A the method's iteration matrix, G = J(q) (m, n),
                                            S (m, m) the equality rows' regularization)

and the contact impulses r enter as K x = b + [W^T r; 0]. So the generalized velocity after
the impulses is x_free + sum_k Y_k r_k with Y_k = K^-1 [W_k^T; 0]: the rows of W padded with m
zero columns (``pad_rows``) go through contact_problem.delassus with K as the factored matrix,
and D = W K^-1 W^T is the Delassus operator of the contacts on the constrained motion (the
constraint impulses respond to the contact impulses exactly, not by iteration). Without
constraints (m = 0) K is A and this is the plain contact problem.

Rows: n_rows = c + WT.shape[0], the normal rows (c) then the tangent rows (WT.shape[0] // c
tangents per contact, rows t c + a); every loop here runs over n_rows and finds the contact of
row k as k % c, so it holds for any number of tangents per contact.

The saved contact fields (moreau_jean's, spook_contacts' SPEC.saved, CONTACT_SAVED): active
contacts (1), the impulses r (n_rows = 3c: normal, tangent 1, tangent 2), the smallest gap at the end of the
step (1), the cumulated work of the contact impulses (1); then the constrained methods' fields
(core/constrained.py) for a model with holonomic constraints: multipliers (m), max|Phi| and
max|J v + dPhi/dt| (1 each, absent without constraints).
"""

import numpy as np
from ...jit.cache import njit

from .options import FAST
from .status import OK

from .contact_problem import contact_row, delassus
from .contact_lcp import contact_solve
from .constrained import max_abs_jv

#: The saved fields of a contact method (see the module docstring; width "m1": 1 with
#: holonomic constraints, 0 without).
CONTACT_SAVED = (("active_contacts", 1), ("normal_impulse", "c"), ("tangent_impulse", "c"),
                 ("tangent2_impulse", "c"), ("min_gap", 1), ("contact_work", 1), ("multipliers", "m"),
                 ("constraint_error", "m1"), ("velocity_constraint_error", "m1"))


#: CONTACT_SAVED of a contact method that also treats nonholonomic constraints (moreau_jean):
#: their multipliers (r) and max|A v + b| at the end of the step (1 with nonholonomic
#: constraints, 0 without) before the holonomic fields, which stay last.
NONHOLONOMIC_CONTACT_SAVED = (CONTACT_SAVED[:6] + (("nonholonomic_multipliers", "r"),
                                                   ("nonholonomic_error", "r1"))
                              + CONTACT_SAVED[6:])


@njit(inline="always")
def min_gap(g):
    """The smallest entry of g (c,) (inf for no contacts)."""
    m = np.inf
    for i in range(g.shape[0]):
        m = min(m, g[i])
    return m


@njit(**FAST)
def contact_prepare(kern, q, v, mom, t, p, settings, ws, extra):
    """A contact method's prepare (the stepper contract, docs/STEPPERS.md): row 0 of the saved
    fields, no active contact, no impulse, the initial smallest gap (ws.g, ws.WN, ws.WT,
    ws.coef and ws.r (n_rows,) of the method's workspace); the contact work continues from what
    extra holds (0 at the start of a run); the constrained fields keep the consistent start
    simulate put there."""
    kern.contacts(q, t, p, ws.g, ws.WN, ws.WT, ws.coef)
    R = ws.r.shape[0]
    for i in range(R + 1):
        extra[i] = 0.0
    extra[R + 1] = min_gap(ws.g)
    return OK


@njit(inline="always")
def assemble_constraint_rows(K, n, G, reg):
    """The equality rows and columns of K (N, N): K[i, n + k] = -G[k, i], K[n + k, j] = G[k, j],
    K[n + k, n + l] = reg if k == l else 0, for G (m, n) and the regularization reg (the
    compliance term Sigma of spook, 0 for rigid rows)."""
    m = G.shape[0]
    for k in range(m):
        for i in range(n):
            K[i, n + k] = -G[k, i]
            K[n + k, i] = G[k, i]
        for j in range(m):
            K[n + k, n + j] = reg if j == k else 0.0


@njit(inline="always")
def pad_rows(n, WN, WT, WNp, WTp):
    """WNp (c, N), WTp (rows of WT, N) <- WN (c, n), WT with zeros in columns n..N-1 (the places
    of the constraint impulses in the KKT unknown)."""
    N = WNp.shape[1]
    for a in range(WN.shape[0]):
        for i in range(N):
            WNp[a, i] = WN[a, i] if i < n else 0.0
    for a in range(WT.shape[0]):
        for i in range(N):
            WTp[a, i] = WT[a, i] if i < n else 0.0


@njit(inline="always")
def row_dot(k, c, WN, WT, v, n):
    """W_k . v over the first n entries (row k of W^T: normal rows, then tangent rows)."""
    w = contact_row(k, c, WN, WT)
    s = 0.0
    for i in range(n):
        s += w[i] * v[i]
    return s


@njit(inline="always")
def solve_contacts(c, N, tol, max_sweeps, active, law, coef, un, uf, WNp, WTp, K, piv, scratch,
                   Y, D, reg, r, lcp):
    """The impulses r (n_rows,) of the active contacts: the Delassus operator D = W K^-1 W^T
    (K LU-factored with pivots piv; Y (n_rows, N) the rows K^-1 [W_k^T; 0]; scratch (N,)), reg
    added to the diagonal of every active row (spook's compliance term, 0 for rigid rows),
    then projected Gauss-Seidel from r = 0 with the free local velocities uf (n_rows,) and the
    approach velocities un (c,) of Newton's impact law, and Lemke's method when Gauss-Seidel
    does not converge (contact_lcp.contact_solve; lcp = its arrays, contact_lcp.lcp_arrays).
    Returns (status: OK, CONTACT_NOT_CONVERGED or CONTACT_NO_SOLUTION, sweeps, change)."""
    n_rows = r.shape[0]
    delassus(c, N, active, WNp, WTp, K, piv, scratch, Y, D)
    for k in range(n_rows):
        if active[k % c] != 0.0:
            D[k, k] += reg
    status, sweeps, change = contact_solve(c, tol, max_sweeps, active, law, coef, un, uf, D, r,
                                           un[:0], lcp[0], lcp[1], lcp[2], lcp[3], lcp[4])
    return status, max_sweeps if sweeps < 0 else sweeps, change


@njit(inline="always")
def apply_impulses(c, active, Y, r, x):
    """x (N,) += sum_k Y_k r_k over the rows of the active contacts: the velocities and the
    constraint impulses after the contact impulses."""
    for k in range(r.shape[0]):
        if active[k % c] != 0.0:
            for i in range(x.shape[0]):
                x[i] += Y[k, i] * r[k]


@njit(inline="always")
def impulse_work(c, n, WN, WT, v_before, v_after, r):
    """The work of the impulses r (n_rows,) in a step: sum_k r_k (u-_k + u+_k) / 2 with
    u- = W v_before, u+ = W v_after (n,) and W at the step's start: the kinetic energy change
    the impulses cause."""
    work = 0.0
    for k in range(r.shape[0]):
        if r[k] != 0.0:
            work += r[k] * 0.5 * (row_dot(k, c, WN, WT, v_before, n)
                                  + row_dot(k, c, WN, WT, v_after, n))
    return work


@njit(inline="always")
def record_contacts(extra, n_active, r, g, work):
    """The contact fields of extra after a step: active count, impulses r (n_rows,), the smallest
    gap g (c,) at the end of the step, and the step's impulse work added to the total."""
    n_rows = r.shape[0]
    extra[0] = n_active
    for k in range(n_rows):
        extra[1 + k] = r[k]
    extra[1 + n_rows] = min_gap(g)
    extra[2 + n_rows] += work


@njit(inline="always")
def record_constraints(extra, start, x, n, scale, phi, G, v, rate):
    """The constrained fields of extra from index start (nothing without constraints): the
    multipliers x[n + k] * scale (m), max|Phi| and max|G v + dPhi/dt| at the end of the step
    (phi, rate (m,), G (m, n) evaluated there)."""
    m = phi.shape[0]
    if m == 0:
        return
    worst = 0.0
    for k in range(m):
        extra[start + k] = x[n + k] * scale
        a = abs(phi[k])
        if a > worst or a != a:
            worst = a
    extra[start + m] = worst
    extra[start + m + 1] = max_abs_jv(G, v, rate)
