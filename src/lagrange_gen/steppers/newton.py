"""The one Newton iteration of every implicit stepper.

A method states its equations as a residual F(x) = 0 in an unknown x (N,) and supplies, as the
attribute ``assemble`` of the module it passes as ``problem``, the jitted assembly

    problem.assemble(kern, args, x, F, J)        F (N,) <- F(x),  J (N, N) <- dF/dx (exact)

``args`` is a tuple of whatever the assembly reads (the state at the start of the step, h, the
parameters, its scratch arrays). ``solve`` then owns everything else: the non-finite check of the
residual, the LU solve of J dx = -F (base.newton_solve: SINGULAR_NEWTON or NON_FINITE when J
cannot be factored), the update x += dx and the one stopping rule (base.newton_converged),
counting iterations.

Why a module and not the assembly function itself: like ``kern`` and ``run_loop``'s ``method``
(see base.py), numba types a module as a compile-time constant with no runtime value, so
``problem.assemble`` is a direct call and the glue of a generated module stays cacheable. A
dispatcher passed as a value, even between jitted functions, is lowered as a process-specific
address: numba then refuses to cache the glue ("uses dynamic globals"; measured on the cart
pendulum's run_midpoint, tests/steppers/test_stepper_cache.py). A method module with one system
passes itself; one with several (partitioned: kick and drift) wraps each assembly with
``problem``.

Speed: ``solve`` and the assemblies are ``inline="always"`` (inlined at numba-IR level into the
method's step), so the loop compiles as if written in the step. As separately compiled
functions taking the args tuple they cost 40-60 ns per step on the cart pendulum (midpoint
about 370 against 320 ns, implicit_euler 280 against 220 ns, best of 5 runs of 2e5 steps).
"""

import math
import sys
import types

from numba import njit

from ..status import NEWTON_DIVERGED, NON_FINITE, OK
from .base import max_abs, newton_converged, newton_solve


def problem(name, assemble):
    """A module (registered in sys.modules as ``name``) whose ``assemble`` is the given jitted
    assembly: what ``solve`` takes as ``problem``."""
    module = types.ModuleType(name, f"Newton system {assemble.__name__} (steppers/newton.py).")
    module.assemble = assemble
    sys.modules[name] = module
    return module


@njit(inline="always")
def solve(problem, kern, args, x, F, J, piv, scratch, tol, max_iter):
    """Newton on problem.assemble's F(x) = 0; x (N,) holds the initial guess and on return the
    last iterate. F, scratch (N,), J (N, N), piv (N,) int64 are workspace.

    Returns (status, iterations, residual): OK when the stopping rule accepted the last update,
    NON_FINITE (F not finite), SINGULAR_NEWTON or NON_FINITE (J could not be factored), or
    NEWTON_DIVERGED after max_iter updates; residual = max|F| at the last assembled iterate."""
    resid = prev = 0.0
    for it in range(1, max_iter + 1):
        problem.assemble(kern, args, x, F, J)
        resid = max_abs(F)
        if not resid < math.inf:        # NaN or inf in F
            return NON_FINITE, it, resid
        status = newton_solve(J, piv, F, scratch)        # F <- J^-1 F = -dx
        if status != OK:
            return status, it, resid
        for i in range(x.shape[0]):
            x[i] -= F[i]
        done, prev = newton_converged(F, x, prev, tol)
        if done:
            return OK, it, resid
    return NEWTON_DIVERGED, max_iter, resid
