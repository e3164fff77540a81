"""The one Newton iteration of every implicit stepper.

A method states its equations as a residual F(x) = 0 in an unknown x (N,) and supplies, as the
attribute ``assemble`` of the module it passes as ``problem``, the jitted assembly

    problem.assemble(kern, args, x, F, J)        F (N,) <- F(x),  J (N, N) <- dF/dx (exact)

``args`` is a tuple of whatever the assembly reads (the state at the start of the step, h, the
parameters, its scratch arrays). ``solve`` then owns everything else: the non-finite check of the
residual, the LU solve of J dx = -F (solve.newton_solve: SINGULAR_NEWTON or NON_FINITE when J
cannot be factored), the update x += dx and the one stopping rule (newton_converged),
counting iterations. ``solve_simplified`` is the same iteration keeping J's factors while the
iteration contracts fast; its problem gives the residual and the Jacobian as two functions.

Why a module and not the assembly function itself: like ``kern`` and ``run_loop``'s ``method``
(see run_loop.py), numba types a module as a compile-time constant with no runtime value, so
``problem.assemble`` is a direct call and the glue of a generated module stays cacheable. A
dispatcher passed as a value, even between jitted functions, is lowered as a process-specific
address: numba then refuses to cache the glue ("uses dynamic globals"; measured on the cart
pendulum's run_midpoint, tests/steppers/test_stepper_cache.py). A method module with one system
passes itself; one with several (partitioned: kick and drift) wraps each assembly with
``problem``.

Speed: ``solve`` and the assemblies are ``inline="always"`` (inlined at numba-IR level into the
method's step), so the loop compiles as if written in the step. As separately compiled
functions taking the args tuple they would cost 40-60 ns more per step on the cart pendulum, a
sixth to a quarter of a midpoint or implicit_euler step there (``lagrange-gen bench steppers``,
reports/steppers.md).
"""

import math
import sys
import types

from ...jit.cache import njit

from .options import FAST
from .solve import max_abs, max_abs_of, newton_solve
from .linalg import lu_solve_inplace
from .status import NEWTON_DIVERGED, NON_FINITE, OK

# The stopping rules of every Newton iteration (solve, solve_simplified, the partitioned and
# nonsmooth methods' own loops).


@njit(cache=True, **FAST)
def increment_small(dx, x, tol):
    """Newton stopping test on the increment, relative to the size of the unknown."""
    return max_abs(dx) <= tol * max(1.0, max_abs(x))


@njit(cache=True, **FAST)
def increment_converged(d, xmax, prev, tol):
    """The stopping rule of newton_converged on precomputed norms: d = max|dx| of this
    iteration, xmax = max|x| after the update, prev = d of the previous iteration (0 on the
    first)."""
    size = tol * max(1.0, xmax)
    if d <= size:
        return True
    if prev > 0.0:
        theta = d / prev
        if theta < 1.0 and theta / (1.0 - theta) * d <= size:
            return True
    return False


@njit(inline="always")
def newton_converged(dx, x, prev, tol, n):
    """Newton stopping test after the update x += dx (both (n,); n passed, options.py, "Loop bounds");
    returns (converged, max|dx|).

    ``prev`` is max|dx| of the previous iteration (0 on the first). Converged when the increment
    is small relative to the unknown, max|dx| <= tol max(1, max|x|), or when the observed
    contraction theta = |dx| / |prev| < 1 bounds the error left in x by theta / (1 - theta) |dx|
    below that (Hairer-Wanner, Solving ODEs II, sec. IV.8): in the quadratic regime this saves
    the last iteration, which would only confirm convergence."""
    d = max_abs_of(dx, n)
    return increment_converged(d, max_abs_of(x, n), prev, tol), d


#: solve_simplified keeps its factored Jacobian while each increment is at most this fraction of
#: the previous one; a slower contraction re-assembles and re-factors J at the current iterate.
THETA_REFRESH = 0.25


def problem(name, assemble=None, *, residual=None, jacobian=None):
    """A module (registered in sys.modules as ``name``) holding a Newton system: ``assemble``
    (what ``solve`` calls), or ``residual(kern, args, x, F)`` and ``jacobian(kern, args, x, J)``
    (what ``solve_simplified`` calls: the residual alone, and J at the iterate the residual was
    last evaluated at, reading what the residual left in ``args``)."""
    module = types.ModuleType(name, f"Newton system {name} (steppers/core/newton.py).")
    module.assemble, module.residual, module.jacobian = assemble, residual, jacobian
    sys.modules[name] = module
    return module


@njit(inline="always")
def solve(problem, kern, args, x, F, J, piv, scratch, tol, max_iter, size):
    """Newton on problem.assemble's F(x) = 0; x (N,) holds the initial guess and on return the
    last iterate. F, scratch (N,), J (N, N), piv (N,) int64 are workspace. size: N (a method
    whose N is kern.N_COORDS passes that, a compile-time constant in a generated module's glue:
    options.py, "Loop bounds"; the others x.shape[0]).

    Returns (status, iterations, residual): OK when the stopping rule accepted the last update,
    NON_FINITE (F not finite), SINGULAR_NEWTON or NON_FINITE (J could not be factored), or
    NEWTON_DIVERGED after max_iter updates; residual = max|F| at the last assembled iterate."""
    resid = prev = 0.0
    for it in range(1, max_iter + 1):
        problem.assemble(kern, args, x, F, J)
        resid = max_abs_of(F, size)
        if not resid < math.inf:        # NaN or inf in F
            return NON_FINITE, it, resid
        status = newton_solve(J, piv, F, scratch)        # F <- J^-1 F = -dx
        if status != OK:
            return status, it, resid
        for i in range(size):
            x[i] -= F[i]
        done, prev = newton_converged(F, x, prev, tol, size)
        if done:
            return OK, it, resid
    return NEWTON_DIVERGED, max_iter, resid


@njit(inline="always")
def solve_simplified(problem, kern, args, x, F, J, piv, scratch, tol, max_iter, factored, size,
                     contraction_stop):
    """Simplified Newton on F(x) = 0 (Hairer-Wanner, Solving ODEs II, sec. IV.8): J = dF/dx is
    assembled (problem.jacobian) and LU-factored at the initial guess and kept; the following
    iterations evaluate F alone (problem.residual) and reuse the factors. While the iteration
    contracts by theta = |dx_k| / |dx_k-1| <= THETA_REFRESH it goes on with the old J; a slower
    contraction (far from the solution, or a Jacobian that changes fast) re-assembles and
    re-factors J at the current iterate, so the worst case is Newton itself. The arguments of
    ``solve`` and ``factored`` (below), the same returns; worth it when the Jacobian and its
    factorization cost much more than a residual and J changes little over the iteration (the
    partitioned kick and drift, whose J is H(q) plus O(h) terms: partitioned.py measures it).
    It stops by newton_converged's rule (increment_converged: the increment below the tolerance,
    or the observed contraction bounding the error left below it) when ``contraction_stop`` is
    True, and on the increment alone when it is False: see the comment in the loop.

    factored: J and piv already hold the LU factors of an approximation of dF/dx (the mass
    matrix H for the kick and the drift, whose Jacobians are H + O(h)): the iteration starts
    with them, and the first Jacobian is assembled only if they contract slowly.

    size: N, the length of x (the partitioned steps pass kern.N_COORDS, a compile-time constant
    in a generated module's glue, so that the loops here unroll: options.py, "Loop bounds")."""
    resid = prev = 0.0
    fresh = not factored
    for it in range(1, max_iter + 1):
        problem.residual(kern, args, x, F)
        resid = max_abs_of(F, size)
        if not resid < math.inf:        # NaN or inf in F
            return NON_FINITE, it, resid
        if fresh:
            problem.jacobian(kern, args, x, J)
            status = newton_solve(J, piv, F, scratch)    # J <- its LU factors, F <- J^-1 F
            if status != OK:
                return status, it, resid
        else:
            lu_solve_inplace(J, piv, F, scratch)
        for i in range(size):
            x[i] -= F[i]
        # The contraction rule stops one iteration earlier than the increment alone, leaving an
        # error up to tol instead of about theta |dx|, far below it. Over many steps an error of
        # tol per solve shows above the round-off floor of a 6th-order composition
        # (tests/zoo/test_heavy_top.py) and in the order of the 4th-order one: the compositions
        # pass False. Verlet and symplectic Euler (orders 2 and 1) pass True, as every other
        # Newton method stops (solve): on the 16-link chain it saves verlet about a quarter of its
        # iterations per step, and as much of its step time.
        d = max_abs_of(F, size)
        if increment_converged(d, max_abs_of(x, size), prev if contraction_stop else 0.0, tol):
            return OK, it, resid
        fresh = prev > 0.0 and not d <= THETA_REFRESH * prev
        prev = d
    return NEWTON_DIVERGED, max_iter, resid
