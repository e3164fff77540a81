"""Small dense linear algebra in numba, in place, no allocation (used by kernels and steppers).

Compiled without numba's reference counting (jit.NO_REFCOUNT): none of these functions allocates,
and with it every call pays atomic increments per array argument (see steppers/core/options.py).

2 x 2 systems (the cart pendulum, every two-coordinate model, and its Newton matrices) take a
path on scalars: the same operations in the same order as the loops, so bitwise the same
result (tests/test_linalg.py), but held in registers instead of re-read from the array after
every store, which makes a 2 x 2 LU solve or Cholesky factor-and-solve several times faster than
the loops over a run-time n.

The substitutions multiply by the reciprocal of each diagonal entry, 1.0 / L[i, i], instead of
dividing by it: the reciprocal does not depend on the running sum, so the divisions leave the
chain of dependent operations that every unknown waits on (each unknown feeds the next
substitution). At most one rounding more per unknown. The back substitutions go column by
column (_back_substitute). Together they take the Cholesky and LU solves at n = 8 to 16 to
about 60 % of the time of dividing, dot-product substitutions. The Cholesky factorization stays
in the dot-product (left-looking) order: column-oriented and right-looking variants are slower
at n = 8 to 24.
"""

import math

from ...jit import NO_REFCOUNT, njit

# Relative pivot threshold below which a matrix is reported singular instead of being factored
# into garbage (e.g. the spherical pendulum's H at sin(q1) = 0).
SINGULAR_RTOL = 1e-13


@njit(cache=True, **NO_REFCOUNT)
def cholesky_inplace(A):
    """Overwrite the lower triangle of the SPD matrix A (n, n) with its Cholesky factor L.

    Returns True on success, False when a pivot is not positive relative to the diagonal scale.
    """
    if A.shape[0] == 2:
        return _cholesky_2(A)
    return _cholesky_loops(A)


@njit(cache=True, **NO_REFCOUNT)
def _cholesky_loops(A):
    """cholesky_inplace for any n."""
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


@njit(cache=True, **NO_REFCOUNT)
def cholesky_solve_inplace(L, b):
    """Solve (L L^T) x = b with L from cholesky_inplace; b (n,) is overwritten by x."""
    if L.shape[0] == 2:
        l00, l10, l11 = L[0, 0], L[1, 0], L[1, 1]
        r00, r11 = 1.0 / l00, 1.0 / l11
        y0 = b[0] * r00
        y1 = (b[1] - l10 * y0) * r11
        x1 = y1 * r11
        b[0] = (y0 - l10 * x1) * r00
        b[1] = x1
    else:
        _cholesky_solve_loops(L, b)


@njit(cache=True, **NO_REFCOUNT)
def _cholesky_solve_loops(L, b):
    """cholesky_solve_inplace for any n."""
    n = L.shape[0]
    for i in range(n):
        s = b[i]
        for k in range(i):
            s -= L[i, k] * b[k]
        b[i] = s * (1.0 / L[i, i])
    # L^T x = y column by column: x_i is final once the rows below have been subtracted, then
    # row i of L (contiguous) updates the entries above it. The dot-product form walks the
    # columns of L (stride n), which is slower (at n = 16 by about 40 %).
    for i in range(n - 1, -1, -1):
        x = b[i] * (1.0 / L[i, i])
        b[i] = x
        for k in range(i):
            b[k] -= L[i, k] * x


@njit(cache=True, **NO_REFCOUNT)
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


@njit(cache=True, **NO_REFCOUNT)
def _cholesky_2(A):
    """cholesky_inplace of a 2 x 2 A on scalars (same operations, same test)."""
    a00, a10, a11 = A[0, 0], A[1, 0], A[1, 1]
    scale = max(max(0.0, abs(a00)), abs(a11))      # the loop's fold, NaN handling included
    if not (scale > 0.0) or not math.isfinite(scale):
        return False
    if not (a00 > SINGULAR_RTOL * scale):
        return False
    l00 = math.sqrt(a00)
    l10 = a10 / l00
    A[0, 0], A[1, 0] = l00, l10
    d = a11 - l10 * l10
    if not (d > SINGULAR_RTOL * scale):
        return False
    A[1, 1] = math.sqrt(d)
    return True


@njit(cache=True, **NO_REFCOUNT)
def _lu_solve_system_2(A, piv, b):
    """lu_solve_system of a 2 x 2 A on scalars: the same pivot choice (swap only for a strictly
    larger entry), singularity test, factors left in A and permutation in piv."""
    a00, a01, a10, a11 = A[0, 0], A[0, 1], A[1, 0], A[1, 1]
    scale = max(max(max(max(0.0, abs(a00)), abs(a01)), abs(a10)), abs(a11))   # the loop's fold
    if not (scale > 0.0) or not math.isfinite(scale):
        return False
    b0, b1 = b[0], b[1]
    piv[0], piv[1] = 0, 1
    swap = abs(a10) > abs(a00)
    big = abs(a10) if swap else abs(a00)
    if not (big > SINGULAR_RTOL * scale):
        return False                            # the loop tests before it swaps
    if swap:
        a00, a01, a10, a11 = a10, a11, a00, a01
        b0, b1 = b1, b0
        piv[0], piv[1] = 1, 0
    f = a10 / a00
    a11 -= f * a01
    b1 -= f * b0
    A[0, 0], A[0, 1], A[1, 0], A[1, 1] = a00, a01, f, a11
    if not (abs(a11) > SINGULAR_RTOL * scale):
        b[0], b[1] = b0, b1                     # where the loop leaves them
        return False
    x1 = b1 * (1.0 / a11)
    b[0] = (b0 - a01 * x1) * (1.0 / a00)
    b[1] = x1
    return True


@njit(cache=True, **NO_REFCOUNT)
def lu_inplace(A, piv):
    """LU factorization with partial pivoting of A (n, n) in place; piv (n,) int64 receives the
    row permutation (solve with lu_solve_inplace). Returns False when a pivot is zero relative
    to the largest entry."""
    return _eliminate(A, piv, A[0, :0])


@njit(cache=True, **NO_REFCOUNT)
def lu_solve_system(A, piv, b):
    """Solve A x = b in one pass: elimination with the right-hand side carried along (no
    separate forward substitution), then back substitution; A (n, n) is left holding its LU
    factors and piv (n,) the permutation (as lu_inplace), b (n,) is overwritten by x. Returns
    False, like lu_inplace, when a pivot is zero relative to the largest entry."""
    if A.shape[0] == 2:
        return _lu_solve_system_2(A, piv, b)
    return _lu_solve_system_loops(A, piv, b)


@njit(cache=True, **NO_REFCOUNT)
def _lu_solve_system_loops(A, piv, b):
    """lu_solve_system for any n."""
    if not _eliminate(A, piv, b):
        return False
    _back_substitute(A, b)
    return True


@njit(cache=True, **NO_REFCOUNT)
def _back_substitute(U, x):
    """Overwrite x (n,) by U^-1 x for the upper triangle of U (n, n), column by column: x_i is
    final once the rows below have been subtracted, then column i of U updates the entries
    above it (each update independent of the others, where the dot-product form waits on its
    running sum)."""
    for i in range(U.shape[0] - 1, -1, -1):
        xi = x[i] * (1.0 / U[i, i])
        x[i] = xi
        for k in range(i):
            x[k] -= U[k, i] * xi


@njit(inline="always")
def cholesky_as_lu(A, piv, n):
    """Rewrite in place the Cholesky factor L of an SPD matrix (lower triangle of A (n, n), from
    cholesky_inplace) as the LU factors of L L^T in lu_inplace's layout: the unit lower factor
    L D^-1 below the diagonal, U = D L^T on and above it (D = diag(L)), piv (n,) the identity;
    lu_solve_inplace then solves with them (the partitioned methods keep the factors of H this
    way as the first matrix of their simplified Newton, steppers/core/partitioned.py). Inlined, with
    n = A.shape[0] passed: solve.factor_mass passes kern.N_COORDS, a compile-time constant in a
    generated module's glue (steppers/core/options.py, "Loop bounds")."""
    for k in range(n):
        piv[k] = k
        d = A[k, k]
        for i in range(k + 1, n):
            A[k, i] = d * A[i, k]
            A[i, k] /= d
        A[k, k] = d * d


@njit(cache=True, **NO_REFCOUNT)
def lu_solve_inplace(LU, piv, b, work):
    """Solve A x = b from lu_inplace's output; b (n,) is overwritten by x, work (n,) is scratch."""
    if LU.shape[0] == 2:        # the loops' operations on scalars (see the module docstring)
        y0, y1 = b[piv[0]], b[piv[1]]
        y1 -= LU[1, 0] * y0
        x1 = y1 * (1.0 / LU[1, 1])
        b[0] = (y0 - LU[0, 1] * x1) * (1.0 / LU[0, 0])
        b[1] = x1
    else:
        _lu_solve_inplace_loops(LU, piv, b, work)


@njit(cache=True, **NO_REFCOUNT)
def _lu_solve_inplace_loops(LU, piv, b, work):
    """lu_solve_inplace for any n."""
    n = LU.shape[0]
    for i in range(n):
        work[i] = b[piv[i]]
    for i in range(n):
        s = work[i]
        for k in range(i):
            s -= LU[i, k] * work[k]
        work[i] = s
    _back_substitute(LU, work)
    for i in range(n):
        b[i] = work[i]
