"""Derivatives of the functions with kinks and jumps that sympy leaves to us.

Differentiating what users write gives functions the kernels must evaluate: Heaviside ->
DiracDelta, Abs -> sign, Min/Max -> Heaviside, Piecewise -> Piecewise; sympy writes all of them.
Some it does not close: DiracDelta itself (zero everywhere but at the jump), the derivative of
a piecewise-constant function (floor, ceiling: ``Derivative(floor(x), x)``, unevaluated), taken
as 0, their value everywhere but at the jump (the kernels' Jacobians and the power there are one
element of the generalized derivative, which is all Newton and the work integral need between
jumps); and those of frac(u) = u - floor(u) and Mod(u, c) = u - c floor(u / c), differentiated
through those identities. Any other unevaluated derivative cannot be printed (symengine, which
the CSE runs in, even drops Derivative(frac(x), x) without a word): refused in one line naming it.
"""

from __future__ import annotations

import numpy as np
import sympy as sp

from ..errors import GenerationError
from ..model.expressions import PIECEWISE_CONSTANT, zero_derivative

__all__ = ["PIECEWISE_CONSTANT", "settle_derivatives", "zero_derivative", "NUMERIC_FUNCTIONS"]



def _through_floor(derivative):
    """d/dx frac(u) or Mod(u, c) as the derivative of its floor form (floor's then set to 0)."""
    inner = derivative.expr
    if isinstance(inner, sp.frac):
        u = inner.args[0]
        form = u - sp.floor(u)
    elif isinstance(inner, sp.Mod) and not inner.args[1].free_symbols & derivative.free_symbols:
        u, c = inner.args
        form = u - c * sp.floor(u / c)
    else:
        return derivative
    return sp.diff(form, *derivative.variable_count)


def settle_derivatives(expr, where="an expression"):
    """``expr`` (sympy) with the derivatives of piecewise-constant functions set to 0, those of
    frac and Mod taken through floor; a GenerationError naming any other unevaluated derivative
    left in it."""
    if not isinstance(expr, sp.Basic) or not expr.has(sp.Derivative):
        return expr
    expr = expr.replace(lambda e: isinstance(e, sp.Derivative), _through_floor)
    expr = expr.replace(zero_derivative, lambda d: sp.S.Zero)
    if expr.has(sp.Subs):       # the chain rule through floor(u / c) leaves Subs(0, ...)
        expr = expr.replace(lambda e: isinstance(e, sp.Subs), lambda e: e.doit())
    left = sorted(expr.atoms(sp.Derivative), key=str)
    if left:
        raise GenerationError(f"{where}: sympy leaves the derivative {left[0]} unevaluated; write "
                              f"the function so that sympy can differentiate it")
    return expr


def _dirac_delta(x, *order):
    """DiracDelta(x) and its derivatives at a number: 0 (see the module docstring)."""
    return np.zeros_like(np.asarray(x, dtype=float))


#: Names lambdify's numpy printer leaves as they are, as callables (the derivation's numeric checks).
NUMERIC_FUNCTIONS = {"DiracDelta": _dirac_delta}
