"""Freezing parameters: substitute numbers for some parameters before derivation.

A frozen parameter disappears from the generated module's PARAMS (its value is folded into the
kernels as a constant, so products like m * g * l shrink to one number) and is recorded in
FROZEN; passing it at run time is an error (lagrange_gen.run.params.resolve_params).
"""

from __future__ import annotations

import copy
import sympy as sp

from ..errors import GenerationError
from ..model.expressions import nonfinite_message


def freeze_model(model, frozen):
    """A copy of ``model`` with the parameters named in ``frozen`` replaced by their values.

    The copy's params and defaults no longer list them; every expression (T, V, dissipation,
    forces, constraints, nonholonomic constraints, element strains and coefficients, contacts) has them substituted.
    """
    by_name = {p.name: p for p in model.params}
    unknown = sorted(set(frozen) - set(by_name))
    if unknown:
        raise GenerationError(f"model {model.name}: cannot freeze {', '.join(unknown)}: not a parameter "
                              f"(parameters: {', '.join(by_name) or 'none'})")
    sub = {by_name[k]: sp.Float(v) if v != int(v) else sp.Integer(int(v)) for k, v in frozen.items()}
    out = copy.copy(model)
    out.T, out.V = model.T.xreplace(sub), model.V.xreplace(sub)
    out.dissipation = model.dissipation.xreplace(sub)
    out.forces = [f.xreplace(sub) for f in model.forces]
    out.constraints = [c.xreplace(sub) for c in model.constraints]
    out.nonholonomic = [c.xreplace(sub) for c in getattr(model, "nonholonomic", ())]
    out.elements = [_freeze_element(e, sub) for e in model.elements]
    out.contacts = [_freeze_element(c, sub) for c in getattr(model, "contacts", ())]
    out.params = [p for p in model.params if p.name not in frozen]
    out.param_defaults = {k: v for k, v in model.param_defaults.items() if k not in frozen}
    _check_finite(model, out, sub)
    return out


def _check_finite(model, frozen_model, sub):
    """GenerationError, one line, when a frozen value makes an expression of ``frozen_model``
    non-finite (k = 0 in x**2 / (2 k)), naming the frozen values it uses and the term."""
    originals = dict(model._all_expressions())
    for where, expr in frozen_model._all_expressions():
        problem = nonfinite_message(where, expr)
        if problem:
            used = [f"{p.name} = {value}" for p, value in sub.items()
                    if p in getattr(originals.get(where), "free_symbols", ())]
            values = ", ".join(used or [f"{p.name} = {value}" for p, value in sub.items()])
            raise GenerationError(f"model {model.name}: freezing {values} makes {problem}")


def _freeze_element(element, sub):
    """A copy of a nonsmooth element with every sympy attribute substituted."""
    out = copy.copy(element)
    for key, value in vars(element).items():
        if isinstance(value, sp.Basic):
            setattr(out, key, value.xreplace(sub))
        elif isinstance(value, tuple) and all(isinstance(v, sp.Basic) for v in value):
            setattr(out, key, tuple(v.xreplace(sub) for v in value))
    return out
