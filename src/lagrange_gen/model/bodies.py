"""Kinetic and gravitational energy of sympy.physics.mechanics bodies, with the kinematic tree kept.

sympy's ``RigidBody.kinetic_energy`` writes every velocity out in the inertial frame: on a
spatial chain the terms triple with every body. Here each frame's orientation N.dcm(F), each
body's angular velocity (in its own frame) and each point's position and velocity (in N) are
computed from its parent's, one product of small matrices per joint, and every entry is an
``Intermediate``: a symbol that stands for its definition (an expression of the coordinates,
velocities, parameters and earlier intermediates). The energies returned are short sums over
these symbols; the derivation differentiates through them (derive/graph.py) and never expands
them.

The walk over sympy's frames and points is model/kinematic_tree.py; when sympy's records are not
available the energies fall back to sympy's own ``kinetic_energy`` and ``pos_from`` with one
warning line: correct, but expanded.
"""

from __future__ import annotations

import warnings

import sympy as sp

from ..errors import ModelError
from .joint_form import remember
from .kinematic_tree import KinematicTree, RecordsMissing

__all__ = ["kinetic_energy", "gravity_potential", "is_constant_force", "constant_force_potential"]


def _bodies(bodies, who):
    me = _me()
    if len(bodies) == 1 and isinstance(bodies[0], (list, tuple)):
        bodies = tuple(bodies[0])
    if not bodies:
        raise ModelError(f"{who}: no bodies given (Particles or RigidBodies)")
    for body in bodies:
        if not isinstance(body, (me.Particle, me.RigidBody)):
            raise ModelError(f"{who}: {body!r} is not a Particle or RigidBody")
    return bodies


def _me():
    import sympy.physics.mechanics as me
    return me


def _check_frame(frame, who):
    if not isinstance(frame, _me().ReferenceFrame):
        raise ModelError(f"{who}: the first argument must be the inertial ReferenceFrame, got {frame!r}")


def _fallback(who, exc):
    warnings.warn(f"lagrange_gen.{who}: sympy's frame and point records were not found "
                  f"({exc}); using sympy's expanded kinematics (slow on deep trees)", stacklevel=3)


def kinetic_energy(frame, *bodies):
    """T = sum over Particles and RigidBodies of 1/2 m v.v + 1/2 w.I w (v of the mass centre in
    ``frame``, w the body's angular velocity, I its central inertia, both in the body's frame):
    a scalar sympy expression over Intermediates (module docstring); give it to Model as T.
    ModelError when ``frame`` is not a ReferenceFrame, a body is neither, or a velocity cannot
    be found."""
    _check_frame(frame, "kinetic_energy")
    bodies = _bodies(bodies, "kinetic_energy")
    me = _me()
    try:
        tree = KinematicTree(frame)
        total, inertias = sp.S.Zero, []
        for body in bodies:
            v = tree.velocity(body.masscenter)
            total += body.mass * v.dot(v) / 2
            if isinstance(body, me.RigidBody):
                w = tree.w(body.frame)
                inertia = tree.dyadic_components(body.central_inertia, body.frame)
                inertias.append(inertia)
                total += (w.T * inertia * w)[0, 0] / 2
        remember(total, frame, bodies, tree, inertias)
        return total
    except RecordsMissing as exc:
        _fallback("kinetic_energy", exc)
    except ValueError as exc:
        raise ModelError(f"kinetic_energy: {exc}") from None
    total = sp.S.Zero
    for body in bodies:
        try:
            total += body.kinetic_energy(frame)
        except ValueError as exc:
            raise ModelError(f"kinetic_energy of {body}: {exc}") from None
    return total


def is_constant_force(frame, load):
    """True for a force at a Point whose vector is constant in ``frame`` (every term in
    ``frame``, components free of the dynamicsymbols and of time): a uniform field such as
    gravity, whose work is a potential."""
    me = _me()
    point, vector = load
    if not isinstance(point, me.Point) or not isinstance(vector, me.Vector):
        return False
    for comps, where in vector.args:
        if where != frame or comps.atoms(sp.core.function.AppliedUndef) or comps.atoms(sp.Derivative):
            return False
        if any(s.name == "t" for s in comps.free_symbols):
            return False
    return True


def constant_force_potential(frame, loads):
    """V = -sum F . r_P of constant forces F at points P ((point, vector) pairs, is_constant_force),
    positions from the nearest fixed point, over Intermediates; None when a point has no fixed
    point to be located from (the loads then stay generalized forces)."""
    try:
        tree = KinematicTree(frame)
        total = sp.S.Zero
        for point, vector in loads:
            total -= tree.components(vector, frame).dot(tree.position(point))
        return total
    except (RecordsMissing, ModelError, ValueError):
        return None


def gravity_potential(frame, gravity, *bodies):
    """V = -sum m gravity . r of the bodies' mass centres (``gravity`` a constant Vector in
    ``frame``, e.g. -g*N.z), positions measured from the nearest fixed point (velocity set to
    zero) they are located from; over Intermediates like kinetic_energy."""
    _check_frame(frame, "gravity_potential")
    bodies = _bodies(bodies, "gravity_potential")
    me = _me()
    if not isinstance(gravity, me.Vector):
        raise ModelError(f"gravity_potential: gravity must be a Vector in {frame}, e.g. -g*{frame}.z; got {gravity!r}")
    try:
        tree = KinematicTree(frame)
        g = tree.components(gravity, frame)
        total = sp.S.Zero
        for body in bodies:
            total -= body.mass * g.dot(tree.position(body.masscenter))
        return total
    except RecordsMissing as exc:
        raise ModelError(f"gravity_potential: sympy's point records were not found ({exc}): "
                         "write V from the positions instead") from None
    except ValueError as exc:
        raise ModelError(f"gravity_potential: {exc}") from None
