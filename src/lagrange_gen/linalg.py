"""Small dense linear algebra in numba, in place, no allocation (used by kernels and steppers).

Compiled without numba's reference counting (``_nrt=False``): none of these functions allocates,
and with it every call pays atomic increments per array argument (see steppers/base.py).
"""

import math

from numba import njit

# Relative pivot threshold below which a matrix is reported singular instead of being factored
# into garbage (e.g. the spherical pendulum's H at sin(q1) = 0).
SINGULAR_RTOL = 1e-13


@njit(cache=True, _nrt=False)
def cholesky_inplace(A):
    """Overwrite the lower triangle of the SPD matrix A (n, n) with its Cholesky factor L.

    Returns True on success, False when a pivot is not positive relative to the diagonal scale.
    """
    n = A.shape[0]
    scale = 0.0
    for i in range(n):
        scale = max(scale, abs(A[i, i]))
    if not (scale > 0.0) or not math.isfinite(scale):
        return False
    for j in range(n):
        d = A[j, j]
        for k in range(j):
            d -= A[j, k] * A[j, k]
        if not (d > SINGULAR_RTOL * scale):
            return False
        d = math.sqrt(d)
        A[j, j] = d
        for i in range(j + 1, n):
            s = A[i, j]
            for k in range(j):
                s -= A[i, k] * A[j, k]
            A[i, j] = s / d
    return True


@njit(cache=True, _nrt=False)
def cholesky_solve_inplace(L, b):
    """Solve (L L^T) x = b with L from cholesky_inplace; b (n,) is overwritten by x."""
    n = L.shape[0]
    for i in range(n):
        s = b[i]
        for k in range(i):
            s -= L[i, k] * b[k]
        b[i] = s / L[i, i]
    for i in range(n - 1, -1, -1):
        s = b[i]
        for k in range(i + 1, n):
            s -= L[k, i] * b[k]
        b[i] = s / L[i, i]


@njit(cache=True, _nrt=False)
def _eliminate(A, piv, b):
    """Gaussian elimination with partial pivoting of A (n, n) in place, leaving its LU factors
    and the row permutation in piv (n,) int64; the swaps and eliminations are applied to b as
    they are made when b has n entries (an empty b: factor only). Returns False when a pivot is
    zero relative to the largest entry (A's scale not finite included)."""
    n = A.shape[0]
    with_b = b.shape[0] == n
    scale = 0.0
    for i in range(n):
        for j in range(n):
            scale = max(scale, abs(A[i, j]))
    if not (scale > 0.0) or not math.isfinite(scale):
        return False
    for i in range(n):
        piv[i] = i
    for k in range(n):
        p = k
        big = abs(A[k, k])
        for i in range(k + 1, n):
            if abs(A[i, k]) > big:
                big = abs(A[i, k])
                p = i
        if not (big > SINGULAR_RTOL * scale):
            return False
        if p != k:
            for j in range(n):
                tmp = A[k, j]
                A[k, j] = A[p, j]
                A[p, j] = tmp
            if with_b:
                tmp = b[k]
                b[k] = b[p]
                b[p] = tmp
            tmpi = piv[k]
            piv[k] = piv[p]
            piv[p] = tmpi
        for i in range(k + 1, n):
            A[i, k] /= A[k, k]
            f = A[i, k]
            for j in range(k + 1, n):
                A[i, j] -= f * A[k, j]
            if with_b:
                b[i] -= f * b[k]
    return True


@njit(cache=True, _nrt=False)
def lu_inplace(A, piv):
    """LU factorization with partial pivoting of A (n, n) in place; piv (n,) int64 receives the
    row permutation (solve with lu_solve_inplace). Returns False when a pivot is zero relative
    to the largest entry."""
    return _eliminate(A, piv, A[0, :0])


@njit(cache=True, _nrt=False)
def lu_solve_system(A, piv, b):
    """Solve A x = b in one pass: elimination with the right-hand side carried along (no
    separate forward substitution), then back substitution; A (n, n) is left holding its LU
    factors and piv (n,) the permutation (as lu_inplace), b (n,) is overwritten by x. Returns
    False, like lu_inplace, when a pivot is zero relative to the largest entry."""
    if not _eliminate(A, piv, b):
        return False
    n = A.shape[0]
    for i in range(n - 1, -1, -1):
        s = b[i]
        for k in range(i + 1, n):
            s -= A[i, k] * b[k]
        b[i] = s / A[i, i]
    return True


@njit(cache=True, _nrt=False)
def lu_solve_inplace(LU, piv, b, work):
    """Solve A x = b from lu_inplace's output; b (n,) is overwritten by x, work (n,) is scratch."""
    n = LU.shape[0]
    for i in range(n):
        work[i] = b[piv[i]]
    for i in range(n):
        s = work[i]
        for k in range(i):
            s -= LU[i, k] * work[k]
        work[i] = s
    for i in range(n - 1, -1, -1):
        s = work[i]
        for k in range(i + 1, n):
            s -= LU[i, k] * work[k]
        work[i] = s / LU[i, i]
    for i in range(n):
        b[i] = work[i]
