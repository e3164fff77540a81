"""The exact fallback of the contact problem: Lemke's complementary pivoting on its LCP.

Projected Gauss-Seidel (contact_problem.py) is cheap and usually converges, but it can stall
where the problem still has a solution: nearly dependent contact rows with friction (two
corners of a slider on one wall) make its sweeps trade impulse between the contacts without
settling. ``contact_solve`` runs Gauss-Seidel first and, when it does not converge, writes
the same problem as a linear complementarity problem

    w = M z + q >= 0,   z >= 0,   z . w = 0      (z, w, q (k,), M (k, k))

and solves it by Lemke's method, which ends either at a solution or on a secondary ray; for
the matrices of frictional contact (copositive-plus once the cone is faceted) a ray means that
no solution exists (Painleve's paradox: sliding friction that would pull the body into the
surface), reported as CONTACT_NO_SOLUTION.

The LCP of the contacts, in the variables z, each contact a (active) giving:

* its normal impulse: one variable p_N >= 0 (UNILATERAL, w = u_N + e min(u_N-, 0)) or two,
  p_N = z+ - z- (BILATERAL, w = +u_N and -u_N: u_N = 0 with p_N of either sign);
* its friction (mu > 0 and a tangent row present), by its tangent law: COULOMB, a faceted
  cone: p_T = sum_j beta_j d_j over the directions d_j (+-t for one tangent, 8 unit vectors of
  the tangent plane for two), beta_j >= 0 with w_j = d_j . u_T + s, and the slip speed s >= 0
  with w_s = mu p_N - sum_j beta_j (the disk replaced by the inscribed octagon; exact in 2D);
  STICK, each tangent row free (split like a bilateral normal, w = u_T); SLIDE_POSITIVE,
  SLIDE_NEGATIVE and SLIDE, no variable: p_T = -mu p_N s folded into the normal's column.

So the impulses are r = B z (B (3c, k)), the complementary quantities w = C u + F z + q0 with
u = uf + D r the local velocities (C (k, 3c)), hence M = C D B + F and q = C uf + q0. Lemke's
tableau T (K, 2K + 2) holds w - M z - z0 e = q (columns: w (K), z (K), z0, right-hand side),
K = LCP_PER_CONTACT c the most variables c contacts need; the first k rows and the used
columns take part. Every array is allocated once per run (``lcp_arrays``); nothing here
allocates.
"""

import math

import numpy as np

from ...jit.cache import njit

from .contact_problem import (BILATERAL, COULOMB, SLIDE, SLIDE_NEGATIVE, SLIDE_POSITIVE, STICK,
                              UNILATERAL, gauss_seidel_sliding)
from .status import CONTACT_NO_SOLUTION, CONTACT_NOT_CONVERGED, OK

#: The most LCP variables one contact needs: 2 (a bilateral normal) + 8 facet directions + 1.
LCP_PER_CONTACT = 11
#: Facet directions of the 3D friction cone (the octagon inscribed in the disk).
CONE_FACETS = 8

#: Added to M's diagonal, relative to its largest entry: redundant rows (two corners of one
#: slider on a wall, a bilateral normal or a sticking tangent split in two) make M singular, and
#: Lemke's pivots on a singular M can end on a ray where a solution exists; M + eps I has one
#: solution when M is positive semidefinite (the minimum-norm one as eps -> 0). Used only when
#: Lemke on M itself ends on a ray (its answer is then off by about eps relative: measured
#: 4e-6 on a problem of unit size).
LCP_REGULARIZATION = 1e-10

#: Lemke's outcomes.
LCP_SOLVED = 0
LCP_RAY = 1             # secondary ray: no solution (for the contact LCPs here)
LCP_MAX_PIVOTS = 2      # cycling in a degenerate problem, or too many pivots


@njit
def lcp_arrays(c):
    """The LCP scratch of c contacts: B (3c, K), C (K, 3c), T (K, 2K + 2), z (K,), basis (K,)
    int64, K = LCP_PER_CONTACT c (see the module docstring)."""
    K, R = LCP_PER_CONTACT * c, 3 * c
    return (np.zeros((R, K)), np.zeros((K, R)), np.zeros((K, 2 * K + 2)), np.zeros(K),
            np.zeros(K, np.int64))


@njit(inline="always")
def _pivot(T, k, K, row, col):
    """Gauss-Jordan pivot of the tableau's first k rows on T[row, col]."""
    width = 2 * K + 2
    piv = T[row, col]
    for j in range(width):
        T[row, j] /= piv
    for i in range(k):
        if i == row:
            continue
        f = T[i, col]
        if f != 0.0:
            for j in range(width):
                T[i, j] -= f * T[row, j]


@njit
def lemke(k, T, basis, z, max_pivots):
    """Lemke's method on the tableau T (module docstring) whose first k rows hold w - M z - z0 e
    = q with w basic (basis[i] = i). Returns LCP_SOLVED (z (k,) the solution), LCP_RAY or
    LCP_MAX_PIVOTS. Ties in the ratio test prefer z0 leaving, then the smallest row."""
    K = T.shape[0]
    rhs, z0 = 2 * K + 1, 2 * K
    for i in range(k):
        z[i] = 0.0
        basis[i] = i
    row, qmin, scale = -1, 0.0, 0.0
    for i in range(k):
        if T[i, rhs] < qmin:
            row, qmin = i, T[i, rhs]
        for j in range(k):
            scale = max(scale, abs(T[i, K + j]))
    if row < 0:
        return LCP_SOLVED                       # q >= 0: z = 0
    tol = 1e-12 * max(scale, 1.0)
    _pivot(T, k, K, row, z0)
    leaving = basis[row]
    basis[row] = z0
    entering = K + leaving                      # the complement of w_row
    for _ in range(max_pivots):
        row, best = -1, np.inf
        for i in range(k):
            a = T[i, entering]
            if a > tol:
                ratio = T[i, rhs] / a
                if row < 0 or ratio < best - 1e-14 * abs(best) or (
                        ratio <= best + 1e-14 * abs(best) and basis[i] == z0):
                    row, best = i, ratio
        if row < 0:
            return LCP_RAY
        _pivot(T, k, K, row, entering)
        leaving = basis[row]
        basis[row] = entering
        if leaving == z0:
            for i in range(k):
                if basis[i] >= K and basis[i] < 2 * K:
                    z[basis[i] - K] = max(T[i, rhs], 0.0)
            return LCP_SOLVED
        entering = K + leaving if leaving < K else leaving - K
    return LCP_MAX_PIVOTS


@njit(inline="always")
def _split(B, C, T, K, row, k):
    """Two variables k, k + 1 for a free impulse on ``row``: z+ - z-, w = +-u_row."""
    B[row, k] = 1.0
    B[row, k + 1] = -1.0
    C[k, row] = 1.0
    C[k + 1, row] = -1.0
    return k + 2


@njit
def build_lcp(c, active, law, coef, un, uf, D, slide, B, C, T, reg):
    """The contact problem (contact_problem.gauss_seidel_sliding's arguments) as the LCP of the
    module docstring in B, C and the tableau T, reg times M's largest diagonal entry added to the
    diagonal of the impulse variables (LCP_REGULARIZATION). Returns k, the number of variables."""
    K, R = T.shape[0], 3 * c
    for i in range(R):
        for j in range(K):
            B[i, j] = 0.0
            C[j, i] = 0.0
    for i in range(K):
        for j in range(2 * K + 2):
            T[i, j] = 0.0
    k = 0
    for a in range(c):
        if active[a] == 0.0 or D[a, a] <= 0.0:
            continue
        e, mu = coef[a, 0], coef[a, 1]
        first = k
        if law[a] == BILATERAL:
            k = _split(B, C, T, K, a, k)
        else:
            B[a, k] = 1.0
            C[k, a] = 1.0
            T[k, 2 * K + 1] = e * min(un[a], 0.0)
            k += 1
        normals = k - first
        t1, t2 = c + a, 2 * c + a
        if mu <= 0.0:
            continue
        one, two = D[t1, t1] > 0.0, D[t2, t2] > 0.0
        if not (one or two):
            continue
        tl = law[t1]
        if tl == SLIDE_POSITIVE or tl == SLIDE_NEGATIVE or tl == SLIDE:
            s1, s2 = 1.0, 0.0
            if tl == SLIDE_NEGATIVE:
                s1 = -1.0
            elif tl == SLIDE:
                s1, s2 = slide[a], slide[c + a]
            for j in range(first, first + normals):
                sign = B[a, j]
                B[t1, j] -= mu * s1 * sign
                B[t2, j] -= mu * s2 * sign
            continue
        if tl == STICK:
            if one:
                k = _split(B, C, T, K, t1, k)
            if two:
                k = _split(B, C, T, K, t2, k)
            continue
        # COULOMB: the faceted cone; the slip speed s is variable k + n_dirs
        n_dirs = 2 if not (one and two) else CONE_FACETS
        s = k + n_dirs
        for j in range(n_dirs):
            if one and two:
                angle = 2.0 * math.pi * j / CONE_FACETS
                d1, d2 = math.cos(angle), math.sin(angle)
            else:
                sign = 1.0 if j == 0 else -1.0
                d1, d2 = (sign, 0.0) if one else (0.0, sign)
            B[t1, k + j] = d1
            B[t2, k + j] = d2
            C[k + j, t1] = d1
            C[k + j, t2] = d2
            T[k + j, K + s] = 1.0                 # F: w_j = d_j . u_T + s
            T[s, K + k + j] = -1.0                # F: w_s = mu p_N - sum beta_j
        for j in range(first, first + normals):
            T[s, K + j] = mu * B[a, j]
        k = s + 1
    # M = C D B + F (F already in T's z columns), q = C uf + q0 (q0 already in T's last column);
    # the tableau holds -M.
    for j in range(k):
        for a in range(R):
            s = 0.0
            for b in range(R):
                s += D[a, b] * B[b, j]
            B_dj = s
            for i in range(k):
                if C[i, a] != 0.0:
                    T[i, K + j] += C[i, a] * B_dj
    diag = 0.0
    for i in range(k):
        diag = max(diag, abs(T[i, K + i]))
    for i in range(k):
        if T[i, K + i] > 0.0:       # impulse variables; a slip speed's row stays exact
            T[i, K + i] += reg * diag
        for j in range(k):
            T[i, K + j] = -T[i, K + j]
        for a in range(R):
            T[i, 2 * K + 1] += C[i, a] * uf[a]
        T[i, i] = 1.0
        T[i, 2 * K] = -1.0
    return k


@njit
def solve_lcp(c, active, law, coef, un, uf, D, r, slide, B, C, T, z, basis):
    """r (3c,) <- B z from Lemke's solution of the contact LCP; Lemke's outcome."""
    k = build_lcp(c, active, law, coef, un, uf, D, slide, B, C, T, 0.0)
    outcome = lemke(k, T, basis, z, 50 * k + 50)
    if outcome == LCP_RAY:       # a singular M, or no solution: once more, regularized
        k = build_lcp(c, active, law, coef, un, uf, D, slide, B, C, T, LCP_REGULARIZATION)
        outcome = lemke(k, T, basis, z, 50 * k + 50)
    if outcome != LCP_SOLVED:
        return outcome
    for i in range(3 * c):
        s = 0.0
        if active[i % c] != 0.0:
            for j in range(k):
                s += B[i, j] * z[j]
        r[i] = s
    return LCP_SOLVED


@njit(inline="always")
def contact_solve(c, tol, max_sweeps, active, law, coef, un, uf, D, r, slide, B, C, T, z,
                  basis):
    """The contact problem: projected Gauss-Seidel from r's values, then Lemke when it does not
    converge. Returns (status, sweeps, change): OK, CONTACT_NO_SOLUTION (a ray: no solution) or
    CONTACT_NOT_CONVERGED (neither converged); sweeps -1 when Lemke's solution is the answer."""
    converged, sweeps, change = gauss_seidel_sliding(c, tol, max_sweeps, active, law, coef, un,
                                                     uf, D, r, slide)
    if converged:
        return OK, sweeps, change
    outcome = solve_lcp(c, active, law, coef, un, uf, D, r, slide, B, C, T, z, basis)
    if outcome == LCP_SOLVED:
        return OK, -1, 0.0
    if outcome == LCP_RAY:
        return CONTACT_NO_SOLUTION, sweeps, change
    return CONTACT_NOT_CONVERGED, sweeps, change
