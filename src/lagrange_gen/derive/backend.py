"""Differentiation backend: symengine when installed (tens of times faster on large models), sympy
otherwise. Both take and return sympy objects, so everything downstream sees one representation.

symengine drops sympy's Symbol subclasses and assumptions; results are mapped back to the
caller's symbols by name. An expression symengine cannot represent falls back to sympy.
"""

from __future__ import annotations

import sympy as sp

try:  # optional accelerator
    import symengine as _se
except ImportError:  # pragma: no cover - exercised only where symengine is absent
    _se = None

BACKEND = "symengine" if _se is not None else "sympy"


def _to_se(expr):
    return _se.sympify(expr)


def _name_map(exprs_sympy, variables):
    names = {}
    for e in exprs_sympy:
        for s in e.free_symbols:
            names[s.name] = s
    for v in variables:
        names[v.name] = v
    return names


def _back(expr_se, names):
    out = sp.sympify(expr_se)
    if not out.free_symbols:
        return out
    return out.xreplace({s: names[s.name] for s in out.free_symbols if s.name in names})


def jacobian(exprs, variables, backend=None):
    """d exprs_i / d variables_j as a sympy Matrix (len(exprs), len(variables))."""
    exprs = list(exprs)
    variables = list(variables)
    if not exprs or not variables:
        return sp.zeros(len(exprs), len(variables))
    if (backend or BACKEND) == "symengine":
        try:
            E = [_to_se(e) for e in exprs]
            V = [_to_se(v) for v in variables]
            names = _name_map(exprs, variables)
            return sp.Matrix(len(E), len(V), [_back(e.diff(v), names) for e in E for v in V])
        except Exception:  # noqa: BLE001  any symengine failure: sympy is slower but always right
            pass
    return sp.Matrix(exprs).jacobian(variables)


def gradient(expr, variables, backend=None):
    """d expr / d variables_j as a sympy column Matrix (len(variables), 1)."""
    return jacobian([expr], variables, backend).T

