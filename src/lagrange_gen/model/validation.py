"""The checks a Model passes once built: names, symbols, and what each kind of expression may
depend on; each failure is one ModelError line naming the model and the culprit."""

from __future__ import annotations

import sympy as sp

from ..errors import ModelError
from .expressions import check_rayleigh, nonfinite_message, settled_later, unknown_symbols_hint
from .intermediates import expand_intermediates
from .symbols import Parameter, check_name, t

__all__ = ["check_model"]


def check_model(model):
    """ModelError naming the model and the offending symbol or expression when ``model``'s
    names clash, an expression uses an unknown symbol or an undefined function or holds
    sympy's zoo, oo or nan (expressions.nonfinite_message), V depends on
    velocities, the dissipation is not a Rayleigh function of the velocities, a constraint is
    not holonomic, an element is malformed, or T has no velocity in it."""
    names = {}
    for kind, syms in (("coordinate", model.coords), ("velocity", model.velocities),
                       ("parameter", model.params)):
        for s in syms:
            check_name(kind, s.name)
            if s.name in names or s.name == "t":
                other = names.get(s.name, "time")
                raise ModelError(f"model {model.name}: duplicate name {s.name!r} ({other} and {kind})")
            names[s.name] = kind
    for name in model.outputs:
        check_name("output", name)
    q, qd = set(model.coords), set(model.velocities)
    allowed = q | qd | set(model.params) | {t} | set(model.intermediates)
    for where, expr in model.input_expressions():
        unknown = sorted(str(s) for s in expr.free_symbols - allowed)
        if unknown:
            raise ModelError(f"model {model.name}: {where} uses symbol(s) {', '.join(unknown)} "
                             "that are neither coordinates, velocities, parameters nor t"
                             + unknown_symbols_hint(expr.free_symbols - allowed))
        nonfinite = nonfinite_message(where, expr)
        if nonfinite:
            raise ModelError(f"model {model.name}: {nonfinite}")
        open_derivatives = [d for d in expr.atoms(sp.Derivative) if not settled_later(d)]
        if open_derivatives or expr.atoms(sp.core.function.AppliedUndef):
            raise ModelError(f"model {model.name}: {where} contains an undefined function or derivative: {expr}")
    moving = [f"{v} ({c}.d)" for c, v in zip(model.coords, model.velocities) if v in model.symbols_of(model.V)]
    if moving:
        raise ModelError(f"model {model.name}: V depends on the velocit{'y' if len(moving) == 1 else 'ies'} "
                         f"{', '.join(moving)}; V is a function of q and t: velocity-dependent "
                         "potentials belong in T or in forces")
    check_rayleigh(model.name, expand_intermediates(model.dissipation), model.velocities)
    if model.symbols_of(model.dissipation) & {t}:
        raise ModelError(f"model {model.name}: dissipation depends on t")
    for i, c in enumerate(model.constraints):
        bad = sorted(str(s) for s in model.symbols_of(c) & qd)
        if bad:
            raise ModelError(f"model {model.name}: constraint {i} ({c}) depends on {', '.join(bad)}; "
                             "constraints= takes holonomic constraints Phi(q, t) = 0; velocity "
                             "constraints A(q, t) . qdot + b = 0 go in nonholonomic=")
    _check_elements(model, qd)
    if not (model.symbols_of(model.T) & qd):
        raise ModelError(f"model {model.name}: T does not depend on any velocity")

def _check_elements(model, qd):
    for e in model.elements:
        bad = sorted(str(s) for s in model.symbols_of(e.strain) & (qd | {t}))
        if bad:
            raise ModelError(f"model {model.name}: element {e.name}: the strain {e.strain} depends on "
                             f"{', '.join(bad)}; a strain must be a function s(q) of the coordinates")
        for label, c in zip(("stiffness/bound", "threshold"), e.coefficients()):
            if c.free_symbols - set(model.params):
                raise ModelError(f"model {model.name}: element {e.name}: {label} {c} must depend on parameters only")
            value = c.xreplace({p: sp.Float(p.default) for p in c.free_symbols
                                if isinstance(p, Parameter) and p.default is not None})
            if e.kind == "dry_friction" and label == "threshold":
                continue
            if value.is_number and not float(value) > 0:
                raise ModelError(f"model {model.name}: element {e.name}: {label} must be > 0, got {c} = {float(value):g}")
