"""Nonsmooth elements: strains s_e(q), their gradients and curvature, and coefficients."""

from __future__ import annotations

import sympy as sp

from .backend import backend_for, jacobian

KIND_CODES = {"saint_venant": 0, "dry_friction": 1}


def derive_elements(model, aux_we):
    """Return dict(elem_s (ne, 1), elem_grad (ne, n), elem_coef (ne, 3), elem_hess_w (n, n)).

    elem_coef rows are (stiffness, threshold, 0) for a Saint-Venant element and (bound, 0, 1)
    for dry friction: the last column is the kind code (KIND_CODES), so jitted steppers read the
    kind from the same array. elem_hess_w = sum_e we_e d2 s_e/dq2 for an input vector we (ne,): the curvature
    term of the Newton tangent of the element forces -k u grad s (zero for linear strains).
    """
    q = list(model.coords)
    n, ne = len(q), len(model.elements)
    if not ne:
        return dict(elem_s=sp.zeros(0, 1), elem_grad=sp.zeros(0, n), elem_coef=sp.zeros(0, 3),
                    elem_hess_w=sp.zeros(n, n))
    s = sp.Matrix([e.strain for e in model.elements])
    # symengine leaves d/du Abs(u) (sign, Min, Piecewise) unevaluated: such strains need sympy.
    backend = backend_for(list(s))
    grad = jacobian(s, q, backend)
    weighted = sp.Matrix([sum((aux_we[e] * grad[e, j] for e in range(ne)), sp.S.Zero) for j in range(n)])
    hess_w = jacobian(weighted, q, backend)
    coef = sp.Matrix([[*e.coefficients(), KIND_CODES[e.kind]] for e in model.elements])
    return dict(elem_s=s, elem_grad=grad, elem_coef=coef, elem_hess_w=hess_w)
