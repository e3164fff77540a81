"""lagrange_gen.steppers.core.linalg, the factorizations every stepper's solves go through, against numpy and
by their defining identities (P A = L U, L L^T = A), including the singular and non-finite
matrices the steppers must report instead of dividing by."""

import math

import numpy as np
import pytest

from lagrange_gen.steppers.core import linalg


def _matrices(seed=0):
    rng = np.random.default_rng(seed)
    for n in (1, 2, 3, 5, 8, 13):
        yield rng.normal(size=(n, n)), rng.normal(size=n)
    # a row swap needed at the first column, and an ill-scaled but regular matrix
    yield np.array([[0.0, 1.0, 2.0], [3.0, 4.0, 5.0], [6.0, 7.0, 9.0]]), np.array([1.0, 2.0, 3.0])
    yield np.diag([1e-8, 1.0, 1e8]) + 0.1, np.array([1.0, -1.0, 2.0])


@pytest.mark.parametrize("A, b", list(_matrices()))
def test_one_pass_solve_equals_factor_then_substitute_and_numpy(A, b):
    n = len(b)
    x = np.linalg.solve(A, b)
    A1, b1, piv1 = A.copy(), b.copy(), np.zeros(n, np.int64)
    assert linalg.lu_solve_system(A1, piv1, b1)
    A2, b2, piv2 = A.copy(), b.copy(), np.zeros(n, np.int64)
    assert linalg.lu_inplace(A2, piv2)
    linalg.lu_solve_inplace(A2, piv2, b2, np.zeros(n))
    cond = np.linalg.cond(A)
    assert np.abs(b1 - x).max() <= 1e-14 * cond * max(1.0, np.abs(x).max())
    np.testing.assert_array_equal(A1, A2)          # the same factors ...
    np.testing.assert_array_equal(piv1, piv2)      # ... and permutation
    L, U = np.tril(A1, -1) + np.eye(n), np.triu(A1)
    np.testing.assert_allclose(L @ U, A[piv1], rtol=1e-13, atol=1e-13 * np.abs(A).max())


@pytest.mark.parametrize("A", [np.zeros((2, 2)), np.array([[1.0, 2.0], [2.0, 4.0]]),
                               np.array([[1.0, math.nan], [0.0, 1.0]]),
                               np.array([[math.inf, 0.0], [0.0, 1.0]])])
def test_singular_or_non_finite_matrices_are_refused(A):
    piv = np.zeros(2, np.int64)
    assert not linalg.lu_solve_system(A.copy(), piv, np.ones(2))
    assert not linalg.lu_inplace(A.copy(), piv)


def _two_by_two(seed=1):
    """2 x 2 matrices for the scalar paths: random (both pivot orders), SPD, near-singular,
    exactly singular, zero, NaN and inf entries."""
    rng = np.random.default_rng(seed)
    mats = [rng.normal(size=(2, 2)) for _ in range(40)]
    mats += [m @ m.T + 1e-3 * np.eye(2) for m in mats[:20]]
    mats += [np.array([[1.0, 2.0], [2.0, 4.0 + 1e-14]]), np.array([[1e-300, 1.0], [1.0, 0.0]]),
             np.zeros((2, 2)), np.array([[1.0, 2.0], [2.0, 4.0]]),
             np.array([[math.nan, 1.0], [1.0, 1.0]]), np.array([[1.0, math.nan], [0.0, 1.0]]),
             np.array([[1.0, 0.0], [math.inf, 1.0]]), np.array([[0.0, 1.0], [1.0, 0.0]])]
    return mats


def _same(a, b):
    np.testing.assert_array_equal(np.asarray(a), np.asarray(b))   # NaN == NaN here


@pytest.mark.parametrize("A", _two_by_two())
def test_two_by_two_scalar_paths_are_bitwise_the_loops(A):
    """The n = 2 paths on scalars (linalg module docstring) give the loops' results bit for bit:
    the return value, the factors left in A, the permutation and the solution."""
    b = np.array([0.7, -1.3])
    A1, b1, p1 = A.copy(), b.copy(), np.zeros(2, np.int64)
    A2, b2, p2 = A.copy(), b.copy(), np.zeros(2, np.int64)
    assert linalg.lu_solve_system(A1, p1, b1) == linalg._lu_solve_system_loops(A2, p2, b2)
    for x, y in ((A1, A2), (p1, p2), (b1, b2)):
        _same(x, y)
    L1, L2 = A.copy(), A.copy()
    ok = linalg.cholesky_inplace(L1)
    assert ok == linalg._cholesky_loops(L2)
    _same(L1, L2)
    if ok:
        c1, c2 = b.copy(), b.copy()
        linalg.cholesky_solve_inplace(L1, c1)
        linalg._cholesky_solve_loops(L2, c2)
        _same(c1, c2)
    F, pf = A.copy(), np.zeros(2, np.int64)
    if linalg.lu_inplace(F, pf):
        c1, c2 = b.copy(), b.copy()
        linalg.lu_solve_inplace(F, pf, c1, np.zeros(2))
        linalg._lu_solve_inplace_loops(F, pf, c2, np.zeros(2))
        _same(c1, c2)


@pytest.mark.parametrize("n", [1, 2, 3, 8, 16])
def test_cholesky_factors_as_lu_solve_and_reconstruct(n):
    """cholesky_as_lu rewrites L (L L^T = A) as unit-lower L D^-1 and U = D L^T: their product
    is A, piv is the identity, and lu_solve_inplace with them solves A x = b as numpy does."""
    rng = np.random.default_rng(n)
    M = rng.normal(size=(n, n))
    A = M @ M.T + n * np.eye(n)
    b = rng.normal(size=n)
    F, piv = A.copy(), np.full(n, -1, np.int64)
    assert linalg.cholesky_inplace(F)
    linalg.cholesky_as_lu(F, piv, n)
    np.testing.assert_array_equal(piv, np.arange(n))
    L, U = np.tril(F, -1) + np.eye(n), np.triu(F)
    np.testing.assert_allclose(L @ U, A, rtol=1e-13, atol=1e-13 * np.abs(A).max())
    x = b.copy()
    linalg.lu_solve_inplace(F, piv, x, np.zeros(n))
    np.testing.assert_allclose(x, np.linalg.solve(A, b), rtol=1e-12, atol=1e-13)
