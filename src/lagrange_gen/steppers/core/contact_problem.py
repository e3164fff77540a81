"""The contact problem of c contacts: impulses (or forces) r = (p_N, p_T1, p_T2) (3c,) on the
local velocities (or accelerations) u = u_free + D r, solved by projected Gauss-Seidel.

W = [W_N^T, W_T^T] (n, 3c) are the contact Jacobians (generated ``contacts``: W_N = dg/dq (c, n),
W_T = d slip/d qdot (2c, n): tangent 1 rows, then tangent 2; a zero row where a contact has no
second tangent (the 2D law) or no friction), A an LU-factored (n, n) matrix (the mass matrix, or
the iteration matrix of a theta step) and D = W A^-1 W^T (3c, 3c) the Delassus operator; Y
(3c, n) holds the rows A^-1 W_k^T, so that the generalized velocity change is sum_k Y_k r_k.
Row k of W^T is contact_row(k, c, WN, WT): W_N's rows (k < c), then W_T's.

Each contact a has a law (``law`` (2c,) int64): the normal entry law[a] is UNILATERAL
(Signorini with Newton's impact law, u_N + e min(u_N-, 0) >= 0 _|_ p_N >= 0) or BILATERAL
(u_N = 0, p_N of either sign: a persistent contact whose force is watched for lift-off); the
tangent entry law[c + a], for the pair (p_T1, p_T2), is COULOMB (the disk
|(p_T1, p_T2)| <= mu p_N; the pair that zeroes (u_T1, u_T2) when it fits, else the one on the
circle opposing the slip it leaves), STICK (u_T = 0, p_T unbounded: the sticking force, watched
against mu p_N), SLIDE_POSITIVE / SLIDE_NEGATIVE (one tangent, sliding with u_T1 > 0 / < 0:
p_T1 = -/+ mu p_N) or SLIDE (3D sliding along the unit direction s_a = (slide[a],
slide[c + a]) of the slip: p_T = -mu p_N s_a). A contact without friction (mu = 0) has p_T = 0
whatever its tangent law; one with a single tangent (its tangent-2 row zero) has the interval
|p_T1| <= mu p_N, the disk's 2D case.

The sweep, contact by contact over the active ones:
p_N <- P_N(p_N - (u_N + e min(u_N-, 0)) / D_NN), then the tangent pair: with one tangent
p_T <- P_T(p_T - u_T / D_TT) (COULOMB: clamp to [-mu p_N, mu p_N]; STICK: as is; SLIDE: -s mu p_N);
with two, p_T <- p_T - B^-1 u_T (B the pair's 2x2 block of D: the exact local stick) and, for
COULOMB when that leaves the disk, the point of the circle of radius R = mu p_N where the local
slip u_T0 + B p_T is opposite to p_T: p_T = -(B + lambda I)^-1 u_T0 with lambda >= 0 such that
|p_T| = R (u_T0 the slip without this contact's tangent impulse; |p_T(lambda)| falls with lambda,
so bisection finds it). Radial projection of the stick pair instead would not be Coulomb's law
when B is not a multiple of I. The sweeps stop when the largest change of a sweep is at most
tol max|r| or after max_sweeps. Used by moreau_jean (impulses of a step: every law
UNILATERAL / COULOMB) and dop853_impacts (impacts at the velocity level, and the forces of the
persistent contacts at the acceleration level).
"""

import math

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
SLIDE = 4               # two tangents: p_T = -mu p_N s, s the given unit slip direction

#: Bisection steps of the disk's boundary point (each halves the bracket of lambda).
DISK_BISECTIONS = 200


@njit(inline="always")
def contact_row(k, c, WN, WT):
    """Row k of W^T (3c, n): W_N's rows, then W_T's (tangent 1, then tangent 2)."""
    return WN[k] if k < c else WT[k - c]


@njit(inline="always")
def delassus(c, n, active, WN, WT, A, piv, scratch, Y, D):
    """Y_k = A^-1 W_k^T (rows of the active contacts; A LU-factored with pivots piv, scratch
    (n,)) and D = W A^-1 W^T (3c, 3c) on them (zero rows and columns for the inactive ones)."""
    for k in range(3 * c):
        if active[k % c] == 0.0:
            continue
        w = contact_row(k, c, WN, WT)
        for i in range(n):
            Y[k, i] = w[i]
        lu_solve_inplace(A, piv, Y[k], scratch)
    for a in range(3 * c):
        for b in range(3 * c):
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
    for b in range(3 * c):
        s += D[k, b] * r[b]
    return s


@njit(inline="always")
def _tangent_1d(tangent_law, mu, pn, pt, u, d):
    """One tangent row: the new p_T from p_T, its local velocity u and D_TT = d."""
    if tangent_law == SLIDE_POSITIVE:
        return -mu * pn
    if tangent_law == SLIDE_NEGATIVE:
        return mu * pn
    out = pt - u / d
    if tangent_law == COULOMB:
        out = min(max(out, -mu * pn), mu * pn)
    return out


@njit(inline="always")
def disk_boundary(b11, b12, b22, w1, w2, radius):
    """The pair p (|p| = radius) with w + B p = -lambda p, lambda >= 0 (B = [[b11, b12],
    [b12, b22]] symmetric positive definite, w the slip without p): p = -(B + lambda I)^-1 w, the
    sliding impulse of Coulomb's disk when the sticking one, -B^-1 w, lies outside it."""
    if radius <= 0.0:
        return 0.0, 0.0
    lo, hi = 0.0, math.sqrt(w1 * w1 + w2 * w2) / radius     # |p(hi)| <= |w| / hi = radius
    p1, p2 = 0.0, 0.0
    for _ in range(DISK_BISECTIONS):
        lam = 0.5 * (lo + hi)
        a11, a22 = b11 + lam, b22 + lam
        det = a11 * a22 - b12 * b12
        p1 = -(a22 * w1 - b12 * w2) / det
        p2 = -(a11 * w2 - b12 * w1) / det
        if p1 * p1 + p2 * p2 > radius * radius:
            lo = lam
        else:
            hi = lam
        if hi - lo <= 1e-16 * hi:
            break
    size = math.sqrt(p1 * p1 + p2 * p2)
    if size > 0.0:
        p1, p2 = p1 * radius / size, p2 * radius / size
    return p1, p2


@njit(inline="always")
def _tangent_pair(tangent_law, mu, pn, t1, t2, a, c, uf, D, r, slide):
    """The tangent pair (rows t1, t2) of contact a with both rows present (module docstring)."""
    radius = mu * pn
    if tangent_law == SLIDE:
        return -radius * slide[a], -radius * slide[c + a]
    if tangent_law == SLIDE_POSITIVE:
        return -radius, 0.0
    if tangent_law == SLIDE_NEGATIVE:
        return radius, 0.0
    b11, b12, b22 = D[t1, t1], 0.5 * (D[t1, t2] + D[t2, t1]), D[t2, t2]
    u1 = local_velocity(t1, c, uf, D, r)
    u2 = local_velocity(t2, c, uf, D, r)
    det = b11 * b22 - b12 * b12
    if det <= 1e-14 * b11 * b22:      # dependent tangent rows: one scaled projected step
        step = 1.0 / max(b11, b22)
        p1, p2 = r[t1] - step * u1, r[t2] - step * u2
        size = math.sqrt(p1 * p1 + p2 * p2)
        if tangent_law == COULOMB and size > radius:
            p1, p2 = p1 * radius / size, p2 * radius / size
        return p1, p2
    p1 = r[t1] - (b22 * u1 - b12 * u2) / det
    p2 = r[t2] - (b11 * u2 - b12 * u1) / det
    if tangent_law != COULOMB or p1 * p1 + p2 * p2 <= radius * radius:
        return p1, p2
    w1 = u1 - b11 * r[t1] - b12 * r[t2]
    w2 = u2 - b12 * r[t1] - b22 * r[t2]
    return disk_boundary(b11, b12, b22, w1, w2, radius)


@njit(inline="always")
def gauss_seidel(c, tol, max_sweeps, active, law, coef, un, uf, D, r):
    """Projected Gauss-Seidel on r (3c,) from its given values, for laws without 3D sliding
    (gauss_seidel_sliding with no directions)."""
    return gauss_seidel_sliding(c, tol, max_sweeps, active, law, coef, un, uf, D, r, un[:0])


@njit(inline="always")
def gauss_seidel_sliding(c, tol, max_sweeps, active, law, coef, un, uf, D, r, slide):
    """Projected Gauss-Seidel on r (3c,) from its given values (see the module docstring).
    coef (c, 2) = (e, mu); un (c,) the normal velocities before an impact (restitution reverses
    an approaching one, un < 0, only; zeros at the acceleration level); slide (2c,) the unit
    slip directions of the contacts whose law is SLIDE (read for those only). Returns
    (converged, sweeps, the last sweep's largest change)."""
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
            t1, t2 = c + a, 2 * c + a
            p1, p2 = 0.0, 0.0
            if mu > 0.0:
                one, two = D[t1, t1] > 0.0, D[t2, t2] > 0.0
                if one and two:
                    p1, p2 = _tangent_pair(law[t1], mu, pn, t1, t2, a, c, uf, D, r, slide)
                elif one:
                    p1 = _tangent_1d(law[t1], mu, pn, r[t1],
                                     local_velocity(t1, c, uf, D, r), D[t1, t1])
                elif two:
                    p2 = _tangent_1d(law[t1], mu, pn, r[t2],
                                     local_velocity(t2, c, uf, D, r), D[t2, t2])
            change = max(change, abs(p1 - r[t1]), abs(p2 - r[t2]))
            r[t1], r[t2] = p1, p2
            largest = max(largest, abs(pn), abs(p1), abs(p2))
        if change <= tol * largest:
            return True, sweep + 1, change
    return False, max_sweeps, change
