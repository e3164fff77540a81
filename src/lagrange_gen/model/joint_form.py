"""The kinematic tree of a kinetic energy built from bodies, in joint form (Featherstone's model).

``lagrange_gen.kinetic_energy`` remembers, for the expression it returns, the bodies and the
frame walk it built it from (``remember``). ``joint_form(T)`` reads that record as a list of
``Link``: for each rigid body its parent body, the coordinates of its joint, the joint's motion
subspace S, the transform from the parent and its spatial inertia. The recursive algorithms
(derive/recursive.py) run over this list; T itself stays the model's (they are checked against
it numerically before they are used).

Every link has a body-fixed origin O: the point nearest the parent on the chain of points that
locates the mass centre from the fixed base, from which the mass centre is fixed in the body
(for a revolute joint built with locatenew, the joint point: the transform from the parent is
then constant but for the rotation). Spatial vectors are (angular; linear) in the link's frame
at O.

``joint_form`` returns None when the energy does not fit: it was not made by kinetic_energy (or
was changed after), a body is a Particle, two bodies share a frame, a body's relative velocity
is not linear in its own joint's velocities, or a coordinate moves two joints.
"""

from __future__ import annotations

from collections import OrderedDict
from dataclasses import dataclass

import numpy as np
import sympy as sp

from .symbols import Coordinate, Velocity, t

__all__ = ["Link", "remember", "joint_form", "constant_folded"]

#: {T: (frame, bodies, kinematics tree)} of the latest energies built from bodies (bounded).
_RECORDS: OrderedDict = OrderedDict()
_KEEP = 64


@dataclass
class Link:
    """One rigid body of the tree, in joint form (sympy over Coordinates and Parameters).

    parent: index of the parent link in the list (-1: the fixed base); coords: the Coordinates of
    its joint (k of them); S: motion subspace (6, k), v_joint = S qd_joint in this link's frame at
    its origin; E: rotation (3, 3) with [x]_link = E [x]_parent; r: position (3, 1) of this
    origin from the parent's origin, in the parent's frame; mass; com: mass centre (3, 1) from
    the origin, in this frame; inertia: central inertia (3, 3) in this frame.
    """

    name: str
    parent: int
    coords: list
    S: sp.Matrix
    E: sp.Matrix
    r: sp.Matrix
    mass: sp.Expr
    com: sp.Matrix
    inertia: sp.Matrix


def remember(T, frame, bodies, tree, inertias):
    """Record how kinetic_energy built ``T`` (read back, on demand, by joint_form); inertias:
    the central inertia (3, 3) of each RigidBody in its frame, as T used it."""
    _RECORDS[T] = (frame, tuple(bodies), tree, tuple(inertias))
    _RECORDS.move_to_end(T)
    while len(_RECORDS) > _KEEP:
        _RECORDS.popitem(last=False)


def joint_form(T):
    """[Link] in parent-first order for an energy made by kinetic_energy; None when ``T`` was
    not made so or does not fit (module docstring)."""
    record = _RECORDS.get(T)
    if record is None:
        return None
    try:
        return _links(*record)
    except (_DoesNotFit, ValueError, TypeError, KeyError):
        return None


class _DoesNotFit(Exception):
    """The bodies do not form a tree of joints this module can describe."""


def _links(frame, bodies, tree, inertias):
    import sympy.physics.mechanics as me
    if not all(isinstance(b, me.RigidBody) for b in bodies) or len(inertias) != len(bodies):
        raise _DoesNotFit("a Particle")
    of_frame = {}
    for i, body in enumerate(bodies):
        if body.frame in of_frame or body.frame == frame:
            raise _DoesNotFit("two bodies share a frame")
        of_frame[body.frame] = i
    parent = {}
    for i, body in enumerate(bodies):
        up = tree.parent_frame(body.frame)
        while up is not None and up not in of_frame and up != frame:
            up = tree.parent_frame(up)
        if up is None:
            raise _DoesNotFit("frame not reached from N")
        parent[i] = of_frame.get(up, -1)
    order = _parent_first(parent)
    index = {i: k for k, i in enumerate(order)}
    origins, links, used = {}, [], set()
    for i in order:
        body, p = bodies[i], parent[i]
        path = tree.point_path(body.masscenter)
        parent_frame = frame if p < 0 else bodies[p].frame
        parent_origin = path[0] if p < 0 else origins[p]
        if parent_origin not in path:
            raise _DoesNotFit("the mass centre is not located from the parent's origin")
        origin, com = _body_fixed_origin(tree, body, path[path.index(parent_origin):])
        origins[i] = origin
        offset = origin.pos_from(parent_origin)
        E = tree.coords(body.frame.dcm(parent_frame))
        r = tree.coords(offset.to_matrix(parent_frame))
        angular = tree.coords(body.frame.ang_vel_in(parent_frame).to_matrix(body.frame))
        linear = tree.coords(offset.dt(parent_frame).to_matrix(body.frame))
        v_joint = sp.Matrix.vstack(angular, linear)
        rates = sorted((s for s in v_joint.free_symbols if isinstance(s, Velocity)), key=str)
        coords = [Coordinate(s.name[:-len("_dot")]) for s in rates]
        if used & set(coords):
            raise _DoesNotFit("a coordinate moves two joints")
        used |= set(coords)
        S = v_joint.jacobian(rates) if rates else sp.zeros(6, 0)
        # S free of the rates and v_joint(rates = 0) = 0: v_joint = S qd_joint exactly
        if S.free_symbols & set(rates) or v_joint.xreplace({s: 0 for s in rates}) != sp.zeros(6, 1):
            raise _DoesNotFit("joint velocity not linear in its rates")
        links.append(Link(str(body.name), index[p] if p >= 0 else -1, coords, constant_folded(S), E, r,
                          sp.sympify(body.mass), com, inertias[i]))
    return links


def constant_folded(matrix, samples=3, rtol=1e-12):
    """``matrix`` with each entry that depends on Coordinates only, and takes the same value at
    ``samples`` random values of them, replaced by that value: sympy writes a joint axis seen
    from the turning frame as R(q)^T a, constant only numerically (a rotation keeps its axis)."""
    rng = np.random.default_rng(20261122)
    out = sp.Matrix(matrix)
    for k, entry in enumerate(matrix):
        symbols = entry.free_symbols
        if not symbols or not all(isinstance(s, Coordinate) for s in symbols):
            continue
        ordered = sorted(symbols, key=str)
        values = [float(entry.xreplace(dict(zip(ordered, map(sp.Float, rng.uniform(-3, 3, len(ordered)))))))
                  for _ in range(samples)]
        if max(values) - min(values) <= rtol * max(1.0, max(abs(v) for v in values)):
            out[k] = sp.Float(values[0])
    return out


def _parent_first(parent):
    """Body indices ordered so that each parent comes before its children."""
    order, placed = [], {-1}
    while len(order) < len(parent):
        ready = [i for i in sorted(parent) if i not in placed and parent[i] in placed]
        if not ready:
            raise _DoesNotFit("frames form no tree")
        order += ready
        placed |= set(ready)
    return order


def _body_fixed_origin(tree, body, candidates):
    """(origin, com (3, 1)): the point of ``candidates`` (from the parent's origin out to the
    mass centre) nearest the parent from which, and from every point after it, the mass
    centre is fixed in the body's frame (walked back from the mass centre: short vectors)."""
    found = None
    for point in reversed(candidates):
        com = tree.coords(body.masscenter.pos_from(point).to_matrix(body.frame))
        if any(isinstance(s, (Coordinate, Velocity)) or s == t for s in com.free_symbols):
            break
        found = (point, com)
    if found is None:
        raise _DoesNotFit("no body-fixed origin")
    return found
