"""Unilateral contacts: a gap g(q, t) >= 0 with Newton restitution and Coulomb friction.

A ``Contact`` says that the gap g(q, t) between two bodies may not become negative. When it
closes, an impulse along W_N = dg/dq reverses the relative normal velocity
u_N = W_N qdot + dg/dt by Newton's law u_N+ = -e u_N- (restitution e in [0, 1]); while it stays
closed the normal impulse keeps it closed. With friction mu > 0 a tangential impulse along
W_T = d(slip)/d(qdot) obeys Coulomb's law on the slip velocity u_T = W_T qdot + b_T(q, t):
2D (one slip velocity): |p_T| <= mu p_N, p_T opposing u_T when it slides; 3D (a pair of slip
velocities along two orthonormal tangents): the disk |(p_T1, p_T2)| <= mu p_N, the pair opposing
(u_T1, u_T2) when it slides. A gap or slip that depends on t is a moving surface (rheonomic).
``Contact.point_on_plane`` builds one from a sympy.physics.mechanics Point and a plane.

The checks (one ModelError line each) run when a Model is built (check_contacts).
"""

from __future__ import annotations

import sympy as sp

from ..errors import ModelError
from .symbols import Parameter, check_name

__all__ = ["Contact", "check_contacts"]


class Contact:
    """A unilateral contact ``gap(q, t) >= 0``.

    gap: expression of the coordinates (parameters, and t for a moving surface) that is positive
        while apart, zero at contact (e.g. ``y - r`` for a ball of radius r above the floor y = 0).
    restitution: Newton's coefficient e in [0, 1] (0: plastic impact, 1: elastic); a number or an
        expression of parameters.
    friction: Coulomb's coefficient mu >= 0 (0: frictionless).
    slip: the tangential slip velocity at the contact, linear in the velocities (e.g. ``x.d``
        for a block sliding along x; ``x.d - w`` on a belt moving at w): the 2D law; or a pair
        ``(u1, u2)``, the slip velocities along two orthonormal tangents of the contact plane
        (e.g. ``(x.d, y.d)`` for a puck on a table z = 0): the 3D friction cone. Required when
        friction is not 0.
    name: label in the generated module (default ``contact_<i>``).

    ``slips`` is the tuple of slip velocities (0, 1 or 2 of them).
    """

    def __init__(self, gap, restitution=0, friction=0, slip=None, name=None):
        self.gap = sp.sympify(gap)
        self.restitution = sp.sympify(restitution)
        self.friction = sp.sympify(friction)
        self.slip_is_pair = isinstance(slip, (tuple, list))
        if slip is None:
            self.slips = ()
        elif self.slip_is_pair:
            self.slips = tuple(sp.sympify(u) for u in slip)
        else:
            self.slips = (sp.sympify(slip),)
        self.name = name

    @property
    def slip(self):
        """The slip velocity (2D), the pair of them (3D), or None (frictionless)."""
        if not self.slips:
            return None
        return self.slips if self.slip_is_pair else self.slips[0]

    @classmethod
    def point_on_plane(cls, point, origin, frame, normal, tangent=None, restitution=0,
                       friction=0, name=None, tangents=None):
        """The contact of a sympy.physics.mechanics Point with a plane fixed in ``frame``.

        point: the Point that may not cross the plane; origin: a Point of the plane, fixed in
        ``frame`` (the inertial frame); normal: the plane's unit normal (a Vector), pointing to
        the side the point stays on; tangent: a unit Vector in the plane along which friction
        acts (one tangent: the 2D law). tangents (3D friction cone, instead of tangent): a pair
        of orthonormal Vectors in the plane, or ``"frame"``: t1 = the axis of ``frame`` least
        aligned with the normal, made orthogonal to it and unit; t2 = normal x t1. Friction
        needs one of them. gap = r_(origin -> point) . normal, slip = (d r_(origin -> point) / dt
        in frame) . tangent (a pair of them with tangents). Coordinates may be the model's
        dynamicsymbols (Model converts them)."""
        r = point.pos_from(origin)
        gap = r.dot(normal)
        velocity = r.dt(frame)
        if tangents is not None:
            if tangent is not None:
                raise ModelError(f"contact {name or '(unnamed)'}: give tangent= (2D) or "
                                 "tangents= (3D), not both")
            pair = _plane_tangents(frame, normal) if tangents == "frame" else tuple(tangents)
            _check_orthonormal(name, normal, pair)
            slip = tuple(velocity.dot(u) for u in pair)
        else:
            slip = None if tangent is None else velocity.dot(tangent)
        return cls(gap=gap, restitution=restitution, friction=friction, slip=slip, name=name)

    def coefficients(self):
        """(restitution, friction): what the generated ``contacts`` kernel writes per contact."""
        return (self.restitution, self.friction)

    def __repr__(self):
        return (f"Contact(gap={self.gap}, restitution={self.restitution}, "
                f"friction={self.friction}, slip={self.slip})")


def _plane_tangents(frame, normal):
    """(t1, t2): t1 the axis of ``frame`` with the smallest normal component (by the parameters'
    defaults where the normal has parameters), made orthogonal to the unit normal; t2 = n x t1."""
    axes = (frame.x, frame.y, frame.z)
    sizes = []
    for axis in axes:
        value = _default_value(sp.sympify(abs(normal.dot(axis))))
        sizes.append(1.0 if value is None else value)
    axis = axes[min(range(3), key=lambda i: sizes[i])]
    t1 = axis - axis.dot(normal) * normal
    t1 = (t1 / sp.sqrt(sp.simplify(t1.dot(t1)))).simplify()
    return t1, normal.cross(t1).simplify()


def _check_orthonormal(name, normal, pair):
    """ModelError unless ``pair`` is two unit Vectors orthogonal to each other and to normal
    (the Coulomb disk is a disk only in an orthonormal tangent basis)."""
    where = f"contact {name or '(unnamed)'}"
    if len(pair) != 2:
        raise ModelError(f"{where}: tangents must be a pair of Vectors or 'frame', got "
                         f"{len(pair)} of them")
    checks = ((pair[0].dot(normal), 0, "t1 . normal"), (pair[1].dot(normal), 0, "t2 . normal"),
              (pair[0].dot(pair[1]), 0, "t1 . t2"), (pair[0].dot(pair[0]), 1, "|t1|^2"),
              (pair[1].dot(pair[1]), 1, "|t2|^2"))
    for value, want, label in checks:
        if sp.simplify(value - want) != 0:
            raise ModelError(f"{where}: the tangents must be orthonormal and in the plane; "
                             f"{label} = {sp.simplify(value)}, not {want}")


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
    depend on the coordinates or depends on velocities, its restitution is outside [0, 1], its
    friction is negative, it has friction without a slip velocity, its slip pair is not a pair,
    or a slip is not W_T(q, t) qdot + b(q, t) (linear in the velocities)."""
    q, qd = set(model.coords), set(model.velocities)
    for c in model.contacts:
        where = f"model {model.name}: contact {c.name}"
        used = model.symbols_of(c.gap)
        if used & qd:
            raise ModelError(f"{where}: the gap {c.gap} depends on velocities; a gap is g(q)")
        if not used & q:
            raise ModelError(f"{where}: the gap {c.gap} does not depend on any coordinate "
                             f"({', '.join(s.name for s in model.coords)})")
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
        if c.slip_is_pair and len(c.slips) != 2:
            raise ModelError(f"{where}: slip must be one slip velocity (2D) or a pair (u1, u2) "
                             f"(3D), got {len(c.slips)} of them")
        if not c.slips:
            if c.friction.is_zero is not True:
                raise ModelError(f"{where}: friction {_shown(c.friction)} without a tangent: give "
                                 "slip=, the slip velocity (e.g. x.d) or a pair of them (3D)")
            continue
        for slip in c.slips:
            _check_slip(model, slip, where, qd)


def _check_slip(model, slip, where, qd):
    """A slip velocity must be W_T(q, t) . qdot + b(q, t): linear in the velocities (b: the
    tangential velocity of a moving surface)."""
    used = model.symbols_of(slip)
    if not used & qd:
        raise ModelError(f"{where}: the slip {slip} does not depend on any velocity; give the "
                         "tangential slip velocity (e.g. x.d), not a position")
    rows = [sp.diff(slip, v) for v in model.velocities]
    if any(model.symbols_of(r) & qd for r in rows):
        raise ModelError(f"{where}: the slip {slip} is not linear in the velocities "
                         "(it must be W_T(q, t) . qdot + b(q, t))")


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
