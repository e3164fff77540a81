"""Rolling without slipping of a wheel (a thin disk) on a plane, from sympy.physics.mechanics
objects: the velocity constraints a model passes as ``nonholonomic=`` and the height that says
the wheel touches the plane (a holonomic constraint, when the coordinates do not already keep
the wheel on it).

The wheel is a disk of radius r about its centre C with unit axle a (fixed in the wheel); the
plane is fixed in the inertial frame N with unit normal n. The wheel's lowest point lies from C
along -u / |u|, u = n - (n . a) a (n with its axle component removed), at the distance r. Rolling
without slipping: the wheel's material point there has no velocity along the plane,
(v_C + omega x r_(C -> contact)) . t_k = 0 for the plane's two tangents t_1, t_2 (its velocity
along n is the rate of the height, zero when the wheel stays on the plane).
"""

from __future__ import annotations

from typing import NamedTuple

import sympy as sp

from ..errors import ModelError


class RollingContact(NamedTuple):
    """What ``rolling_contact`` derives: ``slip`` [two expressions] for ``nonholonomic=``, the
    contact point's velocity along the plane's tangents; ``height`` the lowest point's height
    above the plane (``constraints=[height]`` keeps the wheel on it; None without ``origin``);
    ``to_contact`` the Vector from the centre to the contact point."""

    slip: list
    height: object
    to_contact: object


def rolling_contact(centre, wheel, axle, radius, frame, normal, origin=None, tangents=None):
    """The rolling-without-slipping constraints of a wheel on a plane fixed in ``frame``.

    centre: the wheel's centre (a mechanics Point whose velocity in ``frame`` is defined or can
    be found from its position); wheel: the wheel's ReferenceFrame (its angular velocity in
    ``frame`` is the wheel's); axle: a unit Vector fixed in the wheel along its axle; radius: the
    wheel's radius (a parameter or number); frame: the inertial ReferenceFrame; normal: the
    plane's unit normal, constant in ``frame``, pointing to the wheel's side; origin: a Point of
    the plane fixed in ``frame`` (needed for ``height``); tangents: two unit Vectors along the
    plane (default: the frame's axes least aligned with the normal, made orthonormal). Returns a
    RollingContact; raises ModelError (one line) for a normal that is not constant in ``frame``
    or a wheel lying flat (axle along the normal: no lowest point)."""
    import sympy.physics.mechanics as me
    if not isinstance(frame, me.ReferenceFrame) or not isinstance(wheel, me.ReferenceFrame):
        raise ModelError("rolling_contact: frame and wheel must be sympy.physics.mechanics "
                         "ReferenceFrames")
    n_components = normal.to_matrix(frame)
    if any(c.has(me.dynamicsymbols._t) for c in n_components):
        raise ModelError(f"rolling_contact: the normal {normal} is not constant in {frame}: "
                         f"the plane must be fixed in the inertial frame")
    along_axle = normal.dot(axle)
    u = normal - along_axle * axle
    length = sp.sqrt(sp.expand(u.dot(u)))
    if length == 0:
        raise ModelError("rolling_contact: the axle is along the normal (the wheel lies flat "
                         "on the plane): there is no lowest point")
    to_contact = -radius / length * u
    velocity = centre.vel(frame) + wheel.ang_vel_in(frame).cross(to_contact)
    t1, t2 = _tangents(frame, normal, n_components) if tangents is None else tangents
    slip = [velocity.dot(t1), velocity.dot(t2)]
    height = None
    if origin is not None:
        height = centre.pos_from(origin).dot(normal) - radius * length
    return RollingContact(slip, height, to_contact)


def _tangents(frame, normal, components):
    """Two orthonormal Vectors along the plane: the frame's axis least aligned with the normal,
    its normal part removed, and normal x that one."""
    axes = (frame.x, frame.y, frame.z)
    sizes = [abs(float(c)) if c.is_number else 1.0 for c in components]
    first = axes[sizes.index(min(sizes))]
    t1 = first - first.dot(normal) * normal
    t1 = t1 / sp.sqrt(t1.dot(t1))
    return t1, normal.cross(t1)
