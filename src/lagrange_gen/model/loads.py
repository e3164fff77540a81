"""What acts on a model besides its energies: point forces (by virtual work) and nonsmooth
elements (Saint-Venant, dry friction) on strains s(q)."""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from ..errors import ModelError

__all__ = ["PointForce", "SaintVenant", "DryFriction"]


def is_point_and_vector(where, vector):
    """True for a sympy.physics.mechanics (Point or ReferenceFrame, Vector) pair; imports
    sympy.physics.mechanics only for objects of sympy.physics."""
    if "sympy.physics" not in type(where).__module__:
        return False
    import sympy.physics.mechanics as me
    return isinstance(where, (me.Point, me.ReferenceFrame)) and isinstance(vector, me.Vector)


@dataclass(frozen=True)
class PointForce:
    """A force applied at a point; its generalized force follows from virtual work.

    ``point``: position of the application point, 2 or 3 expressions in q (and t).
    ``force``: the force vector, same length, expressions in q, qdot and t.
    Q_j = sum_k force_k * d point_k / d q_j.

    Or, with sympy.physics.mechanics: ``point`` a mechanics Point and ``force`` a Vector; the
    Model (given its inertial ``frame=``) converts it through the partial velocities of the
    point (lagrange_gen.model.mechanics; ``mechanics`` is then True).
    """

    point: tuple
    force: tuple
    mechanics: bool = False

    def __init__(self, point, force):
        if "sympy.physics" in type(point).__module__ or "sympy.physics" in type(force).__module__:
            if not is_point_and_vector(point, force):
                raise ModelError(f"PointForce: with sympy.physics.mechanics give a Point and a "
                                 f"Vector, got {type(point).__name__} and {type(force).__name__}")
            for key, value in (("point", point), ("force", force), ("mechanics", True)):
                object.__setattr__(self, key, value)
            return
        try:
            point, force = tuple(point), tuple(force)
        except TypeError:
            raise ModelError(f"PointForce: point and force must be sequences of 2 or 3 expressions "
                             f"(or a mechanics Point and Vector), got {point!r} and {force!r}") from None
        point = tuple(sp.sympify(e) for e in point)
        force = tuple(sp.sympify(e) for e in force)
        if len(point) != len(force):
            raise ModelError(f"PointForce: point has {len(point)} components, force has {len(force)}")
        object.__setattr__(self, "point", point)
        object.__setattr__(self, "force", force)


class SaintVenant:
    """A Saint-Venant element: a spring of stiffness k in series with a slider of threshold eta,
    acting on the strain s(q).

    Its internal variable u (the elastic part of s) obeys u' + dpsi_[-eta, eta](u) ∋ s', and it
    exerts the generalized force -k u grad s(q). Give ``threshold`` (eta) or ``yield_force``
    (alpha = k eta). Several elements form the generalized Prandtl model; a parallel spring in V
    gives linear hardening, a dashpot in ``dissipation`` the viscoelastoplastic model.
    """

    kind = "saint_venant"

    def __init__(self, strain, stiffness, threshold=None, yield_force=None, name=None):
        if (threshold is None) == (yield_force is None):
            raise ModelError("SaintVenant: give exactly one of threshold (eta) or yield_force (alpha = k eta)")
        self.strain = sp.sympify(strain)
        self.stiffness = sp.sympify(stiffness)
        self.threshold = (sp.sympify(threshold) if threshold is not None
                          else sp.sympify(yield_force) / self.stiffness)
        self.name = name

    def coefficients(self):
        return (self.stiffness, self.threshold)


class DryFriction:
    """Coulomb friction on the rate of s(q): force -F_d sign(d s/dt) grad s(q), set-valued
    (anywhere in [-F_d, F_d]) when d s/dt = 0. Needs a velocity-level implicit solve."""

    kind = "dry_friction"

    def __init__(self, rate_of, bound, name=None):
        self.strain = sp.sympify(rate_of)
        self.bound = sp.sympify(bound)
        self.name = name

    def coefficients(self):
        return (self.bound, sp.S.Zero)
