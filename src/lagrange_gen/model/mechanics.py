"""sympy.physics.mechanics loads as model input: forces at Points and torques on ReferenceFrames
turned into generalized forces (the energies of bodies are in bodies.py).

A mechanics model uses ``dynamicsymbols`` as coordinates (Model converts them to Coordinates)
and one inertial ReferenceFrame N::

    T = lg.kinetic_energy(N, top)                       # sum of the bodies' kinetic energies in N
    Model("top", coords=[theta, phi, psi], T=T, frame=N,
          forces=[me.Force(P, -m*g*N.z), me.Torque(A, tau*A.z)])

A load is a sympy ``Force(point, vector)`` or ``Torque(frame, vector)`` (sympy >= 1.13), a tuple
``(Point, Vector)`` or ``(ReferenceFrame, Vector)`` as KanesMethod takes them, or
``PointForce(Point, Vector)``. By virtual work through the partial velocities (all in N):

    Q_j = F . d v_P / d qdot_j        (force F at point P)
    Q_j = T . d omega_A / d qdot_j    (torque T on frame A)

sympy.physics.mechanics is imported only when a model uses it.
"""

from __future__ import annotations

import sympy as sp

from ..errors import ModelError
from .loads import PointForce, is_point_and_vector

__all__ = ["is_mechanics_load", "generalized_loads"]


def _me():
    import sympy.physics.mechanics as me
    return me


def is_mechanics_load(item):
    """True for Force, Torque, (Point, Vector), (ReferenceFrame, Vector) and a PointForce whose
    point is a mechanics Point; never imports sympy.physics.mechanics for other items."""
    if isinstance(item, PointForce):
        return item.mechanics
    return isinstance(item, tuple) and len(item) == 2 and is_point_and_vector(*item)


def where_and_vector(item):
    """(Point or ReferenceFrame, Vector) of a load."""
    if isinstance(item, PointForce):
        return item.point, item.force
    return item[0], item[1]


def generalized_loads(loads, frame, speeds, model_name):
    """Q (list of n sympy expressions, still in dynamicsymbols) of mechanics ``loads`` in the
    inertial ``frame``; ``speeds`` (n,) the time derivatives of the coordinate dynamicsymbols.
    ModelError naming the load when a velocity cannot be found or no frame was given."""
    me = _me()
    if frame is None:
        raise ModelError(f"model {model_name}: forces contain sympy.physics.mechanics loads: give "
                         "the inertial frame, Model(..., frame=N), to convert them by virtual work")
    if not isinstance(frame, me.ReferenceFrame):
        raise ModelError(f"model {model_name}: frame= must be a ReferenceFrame, got {frame!r}")
    if not speeds:
        raise ModelError(f"model {model_name}: sympy.physics.mechanics loads need the coordinates "
                         "as dynamicsymbols (q = dynamicsymbols('q')), so that points and frames "
                         "move with them")
    Q = [sp.S.Zero] * len(speeds)
    for i, item in enumerate(loads):
        where, vector = where_and_vector(item)
        kind = "force" if isinstance(where, me.Point) else "torque"
        try:
            velocity = where.vel(frame) if kind == "force" else where.ang_vel_in(frame)
            partials = me.partial_velocity([velocity], speeds, frame)[0]
        except ValueError as exc:
            raise ModelError(f"model {model_name}: load {i} ({kind} on {where}): {exc}") from None
        for j, partial in enumerate(partials):
            Q[j] += vector.dot(partial)
    return Q
