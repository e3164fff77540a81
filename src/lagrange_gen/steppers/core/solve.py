"""Vector helpers and the linear solves of the steppers: max_abs, copy_into, matvec, the mass
solve (Cholesky), the Newton solve (LU) and the status of a failed factorization.

Shapes: vectors (n,), matrices (n, n); a function taking ``n`` loops to it (kern.N_COORDS:
options.py, "Loop bounds").
"""

import math

from ...jit.cache import njit

from . import linalg
from .options import FAST
from .status import NON_FINITE, OK, SINGULAR_NEWTON


@njit(cache=True, **FAST)
def max_abs(x):
    """max |x_i| of a vector (n,); NaN propagates (returns NaN)."""
    return max_abs_of(x, x.shape[0])


@njit(inline="always")
def max_abs_of(x, n):
    """max_abs of x[:n], inlined (n from kern.N_COORDS: options.py, "Loop bounds")."""
    m = 0.0
    for i in range(n):
        a = abs(x[i])
        if a > m or a != a:
            m = a
    return m


@njit(cache=True, **FAST)
def copy_into(dst, src):
    for i in range(src.shape[0]):
        dst[i] = src[i]


@njit(inline="always")
def matvec(A, x, out, n):
    """out = A x for A (n, n), x (n,); n passed (kern.N_COORDS: options.py, "Loop bounds")."""
    for i in range(n):
        s = 0.0
        for j in range(n):
            s += A[i, j] * x[j]
        out[i] = s


# lagrange_gen.steppers.core.linalg is compiled without reference counting too: plain calls.
_cholesky = linalg.cholesky_inplace
_cholesky_solve = linalg.cholesky_solve_inplace
_lu_solve_system = linalg.lu_solve_system


@njit(**FAST)
def mass_solve(H, b):
    """Overwrite b (n,) by H^-1 b with H (n, n) SPD, factored in place. False if singular."""
    if not _cholesky(H):
        return False
    _cholesky_solve(H, b)
    return True


@njit(cache=True, **FAST)
def failed_solve_status(A):
    """Status of a Newton matrix A (N, N) whose factorization just failed: NON_FINITE when A
    holds NaN or inf (non-finite arithmetic in the kernels, e.g. 1/x at x = 0), else
    SINGULAR_NEWTON. The factorizations return before touching A when its scale is not finite,
    and eliminating a NaN or inf leaves NaN behind, so A still shows which case it was."""
    for i in range(A.shape[0]):
        for j in range(A.shape[1]):
            if not math.isfinite(A[i, j]):
                return NON_FINITE
    return SINGULAR_NEWTON


@njit(**FAST)
def newton_solve(A, piv, b, scratch):
    """Overwrite b by A^-1 b for a Newton matrix A (general: Gaussian elimination with partial
    pivoting applied to b as it goes, A left holding its LU factors). Returns OK,
    SINGULAR_NEWTON, or NON_FINITE (see failed_solve_status). scratch (n,) is not needed by
    the one-pass elimination; it stays in the signature of the Newton loop's solve."""
    if not _lu_solve_system(A, piv, b):
        return failed_solve_status(A)
    return OK


@njit(inline="always")
def factor_mass(H, A, piv, n):
    """A (n, n) <- the factors of the SPD mass matrix H in lu_solve_inplace's layout (Cholesky,
    rewritten by linalg.cholesky_as_lu; piv the identity), H unchanged. One factorization then
    serves v = H^-1 (p - b) and the first Newton matrix of the partitioned methods' next kick
    and drift (partitioned.py). False when H is not numerically positive definite. n = H's
    size, passed (kern.N_COORDS: options.py, "Loop bounds")."""
    for i in range(n):
        for j in range(n):
            A[i, j] = H[i, j]
    if not _cholesky(A):
        return False
    linalg.cholesky_as_lu(A, piv, n)
    return True
