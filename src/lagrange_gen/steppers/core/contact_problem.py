"""The contact problem of c contacts: impulses (or forces) r = (p_N, p_T) (2c,) on the local
velocities (or accelerations) u = u_free + D r, solved by projected Gauss-Seidel.

W = [W_N^T, W_T^T] (n, 2c) are the contact Jacobians (generated ``contacts``: W_N = dg/dq,
W_T = d slip/d qdot, rows (c, n)), A an LU-factored (n, n) matrix (the mass matrix, or the
iteration matrix of a theta step) and D = W A^-1 W^T (2c, 2c) the Delassus operator; Y (2c, n)
holds the rows A^-1 W_k^T, so that the generalized velocity change is sum_k Y_k r_k.

Each contact a has a law (``law`` (2c,) int64): the normal entry law[a] is UNILATERAL
(Signorini with Newton's impact law, u_N + e min(u_N-, 0) >= 0 _|_ p_N >= 0) or BILATERAL
(u_N = 0, p_N of either sign: a persistent contact whose force is watched for lift-off); the
tangent entry law[c + a] is COULOMB (|p_T| <= mu p_N, p_T the one that zeroes u_T when it fits,
else on the bound), STICK (u_T = 0, p_T unbounded: the sticking force, watched against mu p_N)
or SLIDE_POSITIVE / SLIDE_NEGATIVE (sliding with u_T > 0 / < 0: p_T = -/+ mu p_N). A contact
without friction (mu = 0) has p_T = 0 whatever its tangent law.

The sweep, contact by contact over the active ones:
p_N <- P_N(p_N - (u_N + e min(u_N-, 0)) / D_NN), then p_T <- P_T(p_T - u_T / D_TT) (COULOMB:
clamp to [-mu p_N, mu p_N]; STICK: as is; SLIDE: -s mu p_N), until the largest change of a sweep
is at most tol max|r| or max_sweeps sweeps. Used by moreau_jean (impulses of a step: every law
UNILATERAL / COULOMB) and dop853_impacts (impacts at the velocity level, and the forces of the
persistent contacts at the acceleration level).
"""

from ...jit.cache import njit

from .linalg import lu_solve_inplace

#: Normal laws.
UNILATERAL = 0
BILATERAL = 1
#: Tangent laws.
COULOMB = 0
STICK = 1
SLIDE_POSITIVE = 2      # u_T > 0: p_T = -mu p_N
SLIDE_NEGATIVE = 3      # u_T < 0: p_T = +mu p_N


@njit(inline="always")
def contact_row(k, c, WN, WT):
    """Row k of W^T (2c, n): W_N's rows, then W_T's."""
    return WN[k] if k < c else WT[k - c]


@njit(inline="always")
def delassus(c, n, active, WN, WT, A, piv, scratch, Y, D):
    """Y_k = A^-1 W_k^T (rows of the active contacts; A LU-factored with pivots piv, scratch
    (n,)) and D = W A^-1 W^T (2c, 2c) on them (zero rows and columns for the inactive ones)."""
    for k in range(2 * c):
        if active[k % c] == 0.0:
            continue
        w = contact_row(k, c, WN, WT)
        for i in range(n):
            Y[k, i] = w[i]
        lu_solve_inplace(A, piv, Y[k], scratch)
    for a in range(2 * c):
        for b in range(2 * c):
            s = 0.0
            if active[a % c] != 0.0 and active[b % c] != 0.0:
                w = contact_row(a, c, WN, WT)
                for i in range(n):
                    s += w[i] * Y[b, i]
            D[a, b] = s


@njit(inline="always")
def local_velocity(k, c, uf, D, r):
    """(u_free + D r)_k, the local velocity (or acceleration) of row k after the impulses r."""
    s = uf[k]
    for b in range(2 * c):
        s += D[k, b] * r[b]
    return s


@njit(inline="always")
def gauss_seidel(c, tol, max_sweeps, active, law, coef, un, uf, D, r):
    """Projected Gauss-Seidel on r (2c,) from its given values (see the module docstring).
    coef (c, 2) = (e, mu); un (c,) the normal velocities before an impact (restitution reverses
    an approaching one, un < 0, only; zeros at the acceleration level). Returns (converged,
    sweeps, the last sweep's largest change)."""
    change = 0.0
    for sweep in range(max_sweeps):
        change, largest = 0.0, 0.0
        for a in range(c):
            if active[a] == 0.0 or D[a, a] <= 0.0:
                continue
            e, mu = coef[a, 0], coef[a, 1]
            pn = r[a] - (local_velocity(a, c, uf, D, r) + e * min(un[a], 0.0)) / D[a, a]
            if law[a] == UNILATERAL:
                pn = max(0.0, pn)
            change = max(change, abs(pn - r[a]))
            r[a] = pn
            t = c + a
            pt = 0.0
            if mu > 0.0 and D[t, t] > 0.0:
                if law[t] == SLIDE_POSITIVE:
                    pt = -mu * pn
                elif law[t] == SLIDE_NEGATIVE:
                    pt = mu * pn
                else:
                    pt = r[t] - local_velocity(t, c, uf, D, r) / D[t, t]
                    if law[t] == COULOMB:
                        pt = min(max(pt, -mu * pn), mu * pn)
            change = max(change, abs(pt - r[t]))
            r[t] = pt
            largest = max(largest, abs(pn), abs(pt))
        if change <= tol * largest:
            return True, sweep + 1, change
    return False, max_sweeps, change
