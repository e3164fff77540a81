"""Nonholonomic (velocity) constraints A(q, t) qdot + b(q, t) = 0.

A rolling contact (a disk on a plane, a sleigh's knife edge) forbids velocities, not positions:
each constraint is an expression linear in the velocities, c(q, qdot, t) = A(q, t) . qdot +
b(q, t), that must vanish along a motion (an ``sp.Eq(lhs, rhs)`` means lhs - rhs). It need not be
the time derivative of any Phi(q): that is what makes it nonholonomic. The constraint forces are
A^T mu (Lagrange-d'Alembert: they do no work on the velocities the constraints allow).

The checks (one ModelError line each) run when a Model is built (check_nonholonomic).
"""

from __future__ import annotations

import sympy as sp

from ..errors import ModelError
from .intermediates import expand_intermediates

__all__ = ["check_nonholonomic"]


def check_nonholonomic(model):
    """ModelError (one line, naming the model and the constraint) when a nonholonomic constraint
    has no velocity in it, has a term that is not linear in the velocities (the term is named),
    or the model also has nonsmooth elements (no method treats those together yet; contacts
    beside them run with moreau_jean).
    Holonomic constraints may come with them (the rolling wheels of a bicycle)."""
    qd = set(model.velocities)
    for i, c in enumerate(model.nonholonomic):
        where = f"model {model.name}: nonholonomic constraint {i} ({c})"
        if not model.symbols_of(c) & qd:
            raise ModelError(f"{where} has no velocity in it; a position constraint Phi(q) = 0 "
                             "belongs in constraints=")
        term = nonlinear_term(expand_intermediates(c), model.velocities)
        if term is not None:
            raise ModelError(f"{where} is not linear in the velocities: the term {term}; write it "
                             "as A(q, t) . qdot + b(q, t)")
    if not model.nonholonomic:
        return
    if model.elements:
        raise ModelError(f"model {model.name}: nonholonomic constraints together with nonsmooth "
                         "elements are not supported by any method yet (contacts are: "
                         "moreau_jean)")


def nonlinear_term(expr, velocities):
    """The first term of ``expr`` (expanded) that is not of the form f(q, t) * qdot_j or
    f(q, t), or None when ``expr`` is linear in the velocities."""
    velocities = list(velocities)
    # A derivative free of velocities proves linearity without expanding (a rolling wheel's
    # constraint expands into thousands of terms); only an expression that fails it is expanded
    # to name the offending term.
    if not any(sp.diff(expr, v).has(*velocities) for v in velocities if expr.has(v)):
        return None
    for term in sp.Add.make_args(sp.expand(expr)):
        if any(sp.diff(term, v).has(*velocities) for v in velocities if term.has(v)):
            return term
    return None
