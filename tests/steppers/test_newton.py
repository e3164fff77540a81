"""The one Newton of the implicit steppers (steppers/core/newton.py), alone on small systems with
known solutions: F(x) = x_i^2 - a_i (root sqrt(a), Jacobian diag(2 x)); a singular Jacobian; a
non-finite residual; the iteration cap."""

import math

import numpy as np
from numba import njit

from lagrange_gen.steppers.core import newton
from lagrange_gen.steppers.core.options import FAST
from lagrange_gen.steppers.core.status import NEWTON_DIVERGED, NON_FINITE, OK, SINGULAR_NEWTON

ROOTS, SINGULAR, NAN_RESIDUAL, INF_JACOBIAN = 0, 1, 2, 3


@njit(**FAST)
def assemble(kern, args, x, F, J):
    """args = (kind, a (n,)); kind selects the system (see the module docstring)."""
    kind, a = args
    n = x.shape[0]
    for i in range(n):
        F[i] = x[i] * x[i] - a[i]
        for j in range(n):
            J[i, j] = 0.0
        J[i, i] = 2.0 * x[i]
    if kind == SINGULAR:
        for j in range(n):
            J[n - 1, j] = J[0, j]          # two equal rows
    elif kind == NAN_RESIDUAL:
        F[n - 1] = math.nan
    elif kind == INF_JACOBIAN:
        J[0, 0] = math.inf


_PROBLEM = newton.problem(__name__ + "._problem", assemble)


@njit
def _solve(kind, a, x, tol, max_iter):
    n = x.shape[0]
    F, scratch = np.zeros(n), np.zeros(n)
    J, piv = np.zeros((n, n)), np.zeros(n, dtype=np.int64)
    return newton.solve(_PROBLEM, None, (kind, a), x, F, J, piv, scratch, tol, max_iter,
                        x.shape[0])


A = np.array([2.0, 3.0, 0.5])
START = np.array([2.0, 1.0, 1.0])


def test_converges_to_the_root_with_its_iteration_count():
    x = START.copy()
    status, iters, resid = _solve(ROOTS, A, x, 1e-12, 50)
    assert status == OK and 3 <= iters <= 8
    assert np.max(np.abs(x - np.sqrt(A))) < 1e-14
    # resid is max|F| at the last assembled iterate, before its (accepted) update
    assert resid < 1e-6


def test_quadratic_convergence():
    """Stopping after k updates (max_iter = k) leaves the k-th iterate in x: its error e_k obeys
    e_{k+1} <= C e_k^2 with C = max |F''| / (2 min |F'|) ~ 1 / (2 sqrt(a)) near the root."""
    errors = []
    for k in range(1, 6):
        x = START.copy()
        status, iters, _ = _solve(ROOTS, A, x, 0.0, k)     # tol 0: never stops early
        assert status == NEWTON_DIVERGED and iters == k
        errors.append(np.max(np.abs(x - np.sqrt(A))))
    pairs = [(e0, e1) for e0, e1 in zip(errors, errors[1:]) if e1 > 1e-15]
    assert len(pairs) >= 2
    for e0, e1 in pairs:
        assert e1 / e0 ** 2 < 1.0 / (2.0 * math.sqrt(A.min()) * 0.5)
    assert errors[-1] < 1e-15 * 10


def test_max_iter_reached_is_newton_diverged():
    x = START.copy()
    status, iters, resid = _solve(ROOTS, A, x, 1e-12, 2)
    assert status == NEWTON_DIVERGED and iters == 2 and math.isfinite(resid) and resid > 1e-6


def test_singular_jacobian_is_singular_newton():
    x = START.copy()
    status, iters, _ = _solve(SINGULAR, A, x, 1e-12, 50)
    assert status == SINGULAR_NEWTON and iters == 1
    assert np.array_equal(x, START)          # no update from an unsolvable system


def test_non_finite_residual_is_non_finite():
    x = START.copy()
    status, iters, resid = _solve(NAN_RESIDUAL, A, x, 1e-12, 50)
    assert status == NON_FINITE and iters == 1 and math.isnan(resid)
    assert np.array_equal(x, START)


def test_non_finite_jacobian_is_non_finite_not_singular():
    x = START.copy()
    status, _, _ = _solve(INF_JACOBIAN, A, x, 1e-12, 50)
    assert status == NON_FINITE


# ---------------------------------------------------------------- simplified Newton
# The same systems as residual and Jacobian, counting evaluations (args = (kind, a, counts),
# counts (2,): [Jacobians, residuals]).

@njit(**FAST)
def residual_counted(kern, args, x, F):
    kind, a, counts = args
    counts[1] += 1.0
    for i in range(x.shape[0]):
        F[i] = x[i] * x[i] - a[i]
    if kind == NAN_RESIDUAL:
        F[x.shape[0] - 1] = math.nan


@njit(**FAST)
def jacobian_counted(kern, args, x, J):
    kind, a, counts = args
    counts[0] += 1.0
    n = x.shape[0]
    for i in range(n):
        for j in range(n):
            J[i, j] = 0.0
        J[i, i] = 2.0 * x[i]
    if kind == SINGULAR:
        for j in range(n):
            J[n - 1, j] = J[0, j]
    elif kind == INF_JACOBIAN:
        J[0, 0] = math.inf


_SIMPLIFIED = newton.problem(__name__ + "._simplified", residual=residual_counted,
                             jacobian=jacobian_counted)


@njit
def _solve_simplified(kind, a, x, tol, max_iter, counts, contraction_stop=False):
    n = x.shape[0]
    F, scratch = np.zeros(n), np.zeros(n)
    J, piv = np.zeros((n, n)), np.zeros(n, dtype=np.int64)
    return newton.solve_simplified(_SIMPLIFIED, None, (kind, a, counts), x, F, J, piv, scratch,
                                   tol, max_iter, False, n, contraction_stop)


def test_simplified_newton_reaches_newtons_root_with_fewer_jacobians():
    """From a start near the root (J barely changes) the factors are reused: one Jacobian for
    all the iterations; the root is Newton's to the tolerance."""
    root = np.sqrt(A)
    x, counts = root * (1 + 1e-3), np.zeros(2)
    status, iters, _ = _solve_simplified(ROOTS, A, x, 1e-13, 50, counts)
    assert status == OK and np.max(np.abs(x - root)) < 1e-13
    assert counts[0] == 1 and counts[1] == iters and iters >= 3


def test_simplified_newtons_contraction_stop_saves_one_iteration_within_the_tolerance():
    """With contraction_stop (verlet, symplectic Euler) the iteration stops when the observed
    contraction bounds the error left below the tolerance: one iteration before the increment
    itself is that small (the compositions' rule), with an error below tol but above the other
    rule's."""
    root, tol = np.sqrt(A), 1e-10
    runs = {}
    for contraction_stop in (False, True):
        x, counts = root * (1 + 1e-3), np.zeros(2)
        status, iters, _ = _solve_simplified(ROOTS, A, x, tol, 50, counts, contraction_stop)
        assert status == OK
        runs[contraction_stop] = iters, np.max(np.abs(x - root))
    (iters_increment, err_increment), (iters_contraction, err_contraction) = runs[False], runs[True]
    assert iters_contraction == iters_increment - 1
    assert err_increment < err_contraction <= tol * np.max(root)


def test_simplified_newton_refactors_when_the_contraction_is_slow():
    """From START (far: the first Jacobian is off by a factor up to 1.7) the contraction is
    slower than THETA_REFRESH, so J is assembled again; it still converges to the root."""
    x, counts = START.copy(), np.zeros(2)
    status, iters, _ = _solve_simplified(ROOTS, A, x, 1e-12, 50, counts)
    # the stopping rule is relative to max(1, |x|) = 1.73 and estimates a linear tail
    assert status == OK and np.max(np.abs(x - np.sqrt(A))) < 1e-11
    assert 1 < counts[0] < iters and counts[1] == iters


def test_simplified_newton_failures_are_newtons():
    for kind, expected in ((SINGULAR, SINGULAR_NEWTON), (NAN_RESIDUAL, NON_FINITE),
                           (INF_JACOBIAN, NON_FINITE)):
        x = START.copy()
        status, iters, _ = _solve_simplified(kind, A, x, 1e-12, 50, np.zeros(2))
        assert status == expected and iters == 1
    x = START.copy()
    status, iters, _ = _solve_simplified(ROOTS, A, x, 1e-12, 2, np.zeros(2))
    assert status == NEWTON_DIVERGED and iters == 2
