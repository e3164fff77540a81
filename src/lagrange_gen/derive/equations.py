"""The derived equations, to read: ``lg.equations(model)`` and ``lagrange-gen equations``.

    H(q) qddot + h(q, qdot) + g(q) = Q(q, qdot, t) + J(q)^T lambda,    Phi(q) = 0,
    J(q) qddot = gamma(q, qdot)     (gamma = -(dJ/dq . qdot) qdot, the constraints differentiated
                                     twice in time)

H (n, n) is the mass matrix d2T/dqdot2, h (n, 1) the Coriolis/centrifugal terms, g (n, 1) = dV/dq,
Q (n, 1) the generalized forces (forces= and -dD/dqdot of the dissipation), Phi (m, 1) the
constraints, J (m, n) = dPhi/dq. They come from the same derivation the code generator prints
(lagrange_gen.derive), as sympy matrices; entries small enough are simplified.
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

#: Entries with at most this many operations (sp.count_ops) are simplified; larger ones are
#: left as derived (simplify's cost grows quickly with size, and big entries rarely shrink).
SIMPLIFY_MAX_OPS = 80
#: Models with more coordinates than this are not simplified at all.
SIMPLIFY_MAX_COORDS = 12

NAMES = ("H", "h", "g", "Q", "Phi", "J", "gamma")
MEANING = {"H": "mass matrix d2T/dqdot2", "h": "Coriolis and centrifugal terms",
           "g": "conservative forces dV/dq", "Q": "generalized forces (forces and -dD/dqdot)",
           "Phi": "holonomic constraints Phi(q) = 0", "J": "constraint Jacobian dPhi/dq",
           "gamma": "-(dJ/dq . qdot) qdot, so that J qddot = gamma"}


@dataclass
class Equations:
    """H (n, n), h, g, Q (n, 1), Phi (m, 1), J (m, n), gamma (m, 1) as sympy Matrices, and the
    model's coordinates, velocities and parameters (sympy symbols, PARAMS order)."""

    name: str
    coords: list
    velocities: list
    params: list
    H: sp.Matrix
    h: sp.Matrix
    g: sp.Matrix
    Q: sp.Matrix
    Phi: sp.Matrix
    J: sp.Matrix
    gamma: sp.Matrix

    def items(self):
        """(name, matrix) in the order H, h, g, Q, Phi, J, gamma, without the empty constraint
        matrices of an unconstrained model."""
        return [(k, getattr(self, k)) for k in NAMES if getattr(self, k).shape[0]]

    def __str__(self):
        head = (f"model {self.name}: H qddot + h + g = Q" + (" + J^T lambda" if self.Phi.shape[0] else "")
                + f"\ncoordinates q = ({', '.join(map(str, self.coords))}), "
                f"velocities ({', '.join(map(str, self.velocities))}), "
                f"parameters ({', '.join(map(str, self.params)) or 'none'})")
        parts = [f"{k} ({MEANING[k]}) =\n{sp.pretty(v, use_unicode=False, wrap_line=False)}"
                 for k, v in self.items()]
        return "\n\n".join([head] + parts)

    def latex(self):
        """One LaTeX display equation per matrix, e.g. ``H = \\left[...\\right]``."""
        return "\n".join(f"{k} = {sp.latex(v)}" for k, v in self.items())


def equations(model, simplify=True, **options) -> Equations:
    """The equations of motion of ``model`` (a Model, or the path of a model file, with
    ``options`` for its build()) as an :class:`Equations` of sympy matrices.

    simplify: simplify entries with at most SIMPLIFY_MAX_OPS operations (models with at most
    SIMPLIFY_MAX_COORDS coordinates); False returns them as derived.
    """
    from . import derive
    from ..model.model import Model
    from ..model.model_file import load_model
    if not isinstance(model, Model):
        model = load_model(model, **options)
    d = derive(model)
    tidy = _simplifier(simplify and d.n <= SIMPLIFY_MAX_COORDS)
    mats = {k: sp.Matrix(getattr(d, k)).applyfunc(tidy) for k in NAMES}
    return Equations(model.name, list(model.coords), list(model.velocities), list(model.params),
                     **mats)


def _simplifier(enabled):
    def tidy(expr):
        if not enabled or sp.count_ops(expr) > SIMPLIFY_MAX_OPS:
            return expr
        return sp.simplify(expr)
    return tidy
