"""Unilateral contacts: a gap g(q) >= 0 with Newton restitution and Coulomb friction.

A ``Contact`` says that the gap g(q) between two bodies may not become negative. When it closes,
an impulse along W_N = dg/dq reverses the normal velocity u_N = W_N qdot by Newton's law
u_N+ = -e u_N- (restitution e in [0, 1]); while it stays closed the normal impulse keeps it
closed. With friction mu > 0 a tangential impulse along W_T = d(slip)/d(qdot) obeys Coulomb's
law on the slip velocity u_T = W_T qdot: |p_T| <= mu p_N, and p_T opposes u_T when it slides.
2D contacts: one slip velocity per contact (the 3D friction cone is not implemented).
``Contact.point_on_plane`` builds one from a sympy.physics.mechanics Point and a plane.

The checks (one ModelError line each) run when a Model is built (check_contacts).
"""

from __future__ import annotations

import sympy as sp

from ..errors import ModelError
from .symbols import Parameter, check_name, t

__all__ = ["Contact", "check_contacts"]


class Contact:
    """A unilateral contact ``gap(q) >= 0``.

    gap: expression of the coordinates (and parameters) that is positive while apart, zero at
        contact (e.g. ``y - r`` for a ball of radius r above the floor y = 0).
    restitution: Newton's coefficient e in [0, 1] (0: plastic impact, 1: elastic); a number or an
        expression of parameters.
    friction: Coulomb's coefficient mu >= 0 (0: frictionless).
    slip: the tangential slip velocity at the contact, linear in the velocities (e.g. ``x.d``
        for a block sliding along x); required when friction is not 0.
    name: label in the generated module (default ``contact_<i>``).
    """

    def __init__(self, gap, restitution=0, friction=0, slip=None, name=None):
        self.gap = sp.sympify(gap)
        self.restitution = sp.sympify(restitution)
        self.friction = sp.sympify(friction)
        self.slip = None if slip is None else sp.sympify(slip)
        self.name = name

    @classmethod
    def point_on_plane(cls, point, origin, frame, normal, tangent=None, restitution=0,
                       friction=0, name=None):
        """The contact of a sympy.physics.mechanics Point with a plane fixed in ``frame``.

        point: the Point that may not cross the plane; origin: a Point of the plane, fixed in
        ``frame`` (the inertial frame); normal: the plane's unit normal (a Vector), pointing to
        the side the point stays on; tangent: a unit Vector in the plane along which friction
        acts (required with friction; one tangent: the 2D law). gap = r_(origin -> point) . normal,
        slip = (d r_(origin -> point) / dt in frame) . tangent. Coordinates may be the model's
        dynamicsymbols (Model converts them)."""
        r = point.pos_from(origin)
        gap = r.dot(normal)
        slip = None if tangent is None else r.dt(frame).dot(tangent)
        return cls(gap=gap, restitution=restitution, friction=friction, slip=slip, name=name)

    def coefficients(self):
        """(restitution, friction): what the generated ``contacts`` kernel writes per contact."""
        return (self.restitution, self.friction)

    def __repr__(self):
        return (f"Contact(gap={self.gap}, restitution={self.restitution}, "
                f"friction={self.friction}, slip={self.slip})")


def _default_value(expr):
    """``expr`` with the parameters' defaults substituted, as a float, or None when some
    parameter has no default."""
    sub = {p: sp.Float(p.default) for p in expr.free_symbols
           if isinstance(p, Parameter) and p.default is not None}
    value = expr.xreplace(sub)
    return float(value) if value.is_number else None


def _shown(value):
    """A coefficient for a message: ``0.3``, or ``e = 2`` for one given by parameters."""
    number = _default_value(value)
    if value.is_number or number is None:
        return f"{float(value):g}" if value.is_number else str(value)
    return f"{value} = {number:g}"


def check_contacts(model):
    """ModelError (one line, naming the model and the contact) when a contact's gap does not
    depend on the coordinates or depends on velocities or t, its restitution is outside [0, 1],
    its friction is negative, it has friction without a slip velocity, or its slip is not a
    linear form W_T(q) qdot of the velocities."""
    q, qd = set(model.coords), set(model.velocities)
    for c in model.contacts:
        where = f"model {model.name}: contact {c.name}"
        used = model.symbols_of(c.gap)
        if used & qd:
            raise ModelError(f"{where}: the gap {c.gap} depends on velocities; a gap is g(q)")
        if not used & q:
            raise ModelError(f"{where}: the gap {c.gap} does not depend on any coordinate "
                             f"({', '.join(s.name for s in model.coords)})")
        if t in used:
            raise ModelError(f"{where}: the gap {c.gap} depends on t; rheonomic gaps g(q, t) are "
                             "not supported yet")
        for label, value in (("restitution", c.restitution), ("friction", c.friction)):
            if value.free_symbols - set(model.params):
                raise ModelError(f"{where}: {label} {value} must depend on parameters only")
            number = _default_value(value)
            if number is None:
                continue
            if label == "restitution" and not 0.0 <= number <= 1.0:
                raise ModelError(f"{where}: restitution must be in [0, 1], got {_shown(value)}")
            if label == "friction" and not number >= 0.0:
                raise ModelError(f"{where}: friction must be >= 0, got {_shown(value)}")
        if c.slip is None:
            if c.friction.is_zero is not True:
                raise ModelError(f"{where}: friction {_shown(c.friction)} without a tangent: give "
                                 "slip=, the slip velocity (e.g. x.d)")
            continue
        _check_slip(model, c, where, qd)


def _check_slip(model, c, where, qd):
    """The slip velocity must be W_T(q) . qdot: linear and homogeneous in the velocities."""
    used = model.symbols_of(c.slip)
    if t in used:
        raise ModelError(f"{where}: the slip {c.slip} depends on t; rheonomic tangents are not "
                         "supported yet")
    if not used & qd:
        raise ModelError(f"{where}: the slip {c.slip} does not depend on any velocity; give the "
                         "tangential slip velocity (e.g. x.d), not a position")
    velocities = model.velocities
    rows = [sp.diff(c.slip, v) for v in velocities]
    rest = sp.simplify(c.slip - sum((r * v for r, v in zip(rows, velocities)), sp.S.Zero))
    if rest != 0 or any(model.symbols_of(r) & qd for r in rows):
        raise ModelError(f"{where}: the slip {c.slip} is not linear in the velocities "
                         "(it must be W_T(q) . qdot)")


def named_contacts(model_name, contacts):
    """The contacts as a list, each named (``contact_<i>`` by default), each a Contact."""
    out = []
    for i, c in enumerate(contacts):
        if not isinstance(c, Contact):
            raise ModelError(f"model {model_name}: contact {i} is {type(c).__name__}, not Contact")
        c.name = c.name or f"contact_{i}"
        check_name("contact", c.name)
        out.append(c)
    return out
