"""Kinematic trees as plain data, built into sympy.physics.mechanics bodies and a lagrange_gen Model.

A tree is a list of joints (``TREE`` in models/ur5.py, models/spatial_chain.py,
models/humanoid.py), each a dict::

    {"name": "elbow", "parent": 1,            # index of the parent joint, -1: the fixed base
     "link": "forearm_link",                  # optional: the URDF link it moves (a label)
     "type": "revolute",                      # or "prismatic"
     "axis": (0, 1, 0),                       # joint axis in the joint's frame
     "origin": (0, -0.1197, 0.425),           # the joint in the parent joint's frame
     "rpy": (0, 0, 0),                        # optional: the joint frame turned as URDF's rpy
     "mimic": {"joint": "shoulder", "multiplier": 1, "offset": 0},   # optional, below
     "limits": (-3.1, 3.1),                   # optional: contacts with model_from_tree(limits=True)
     "mass": 2.275, "com": (0, 0.0265, 0.11993),     # centre of mass in this body's frame
     "inertia": (ixx, iyy, izz, ixy, iyz, izx)}      # about the com, in this body's frame

Parents come before their children. Body i's frame is the parent's frame moved to ``origin``,
turned by the fixed rotation ``rpy`` (URDF's: Rz(yaw) Ry(pitch) Rx(roll); none when the key is
absent) and then turned by q_i about ``axis`` (revolute) or slid by q_i along it (prismatic).
Without rpy every frame is parallel to the base frame N at q = 0 (N's z axis points up), as in
a URDF with rpy = 0 everywhere, so a peer builds the same model from the same table
(lagrange_gen.bench.robots_peers.pinocchio_model); model/urdf.py writes tables with rpy. A joint
with ``mimic`` has no coordinate of its own: it turns (slides) by multiplier * q_joint + offset
of the named joint (URDF's mimic joints). A link may have no mass (mass 0, inertia 0).

``tree_bodies`` is what a robotics engineer writes with sympy.physics.mechanics: frames oriented
with ``orientnew(..., "Axis", ...)``, points placed with ``locatenew`` from the fixed base point O
(the only velocity set: every other one follows from the positions, as sympy's Point.vel finds
it; a velocity set on a moving point with v2pt_theory would be taken as given, written out in N,
by a structured lg.kinetic_energy), a RigidBody with its full inertia tensor about its mass
centre per joint.
"""

from __future__ import annotations

import math

import numpy as np
import sympy as sp

from .bodies import gravity_potential, kinetic_energy
from .model import Model
from .symbols import parameters

__all__ = ["tree_bodies", "model_from_tree", "check_tree", "n_dof", "rpy_matrix"]

KINDS = ("revolute", "prismatic", "floating")
#: the coordinates of a floating joint, after its name: the position of its origin in N, then the
#: angles of its frame, turned about its own x, then y, then z (sympy's "Body" XYZ)
FLOATING = ("x", "y", "z", "rx", "ry", "rz")


def check_tree(tree):
    """ValueError naming the joint when the table is not a tree as described above."""
    names = set()
    for i, joint in enumerate(tree):
        name = joint.get("name", f"joint {i}")
        if name in names:
            raise ValueError(f"tree: joint name {name!r} used twice")
        names.add(name)
        if joint["type"] not in KINDS:
            raise ValueError(f"tree: joint {name}: type must be one of {KINDS}, got {joint['type']!r}")
        if not -1 <= int(joint["parent"]) < i:
            raise ValueError(f"tree: joint {name}: parent {joint['parent']} must be -1 or an "
                             f"earlier joint (< {i})")
        if joint["type"] == "floating" and (int(joint["parent"]) != -1 or "mimic" in joint):
            raise ValueError(f"tree: joint {name}: a floating joint has the base as parent and no mimic")
        if joint["type"] != "floating" and sum(float(a) ** 2 for a in joint["axis"]) < 1e-24:
            raise ValueError(f"tree: joint {name}: zero axis")
        if len(joint.get("origin", ())) != 3 and joint["type"] != "floating" or len(joint["com"]) != 3 \
                or len(joint["inertia"]) != 6:
            raise ValueError(f"tree: joint {name}: origin and com need 3 numbers, inertia 6")
        if not float(joint["mass"]) >= 0 or len(joint.get("rpy", (0, 0, 0))) != 3:
            raise ValueError(f"tree: joint {name}: mass must be >= 0, rpy 3 numbers")
        if "limits" in joint and not float(joint["limits"][0]) < float(joint["limits"][1]):
            raise ValueError(f"tree: joint {name}: limits must be (lower, upper) with lower < upper")
    for joint in tree:
        mimic = joint.get("mimic")
        if mimic is not None and not any(j["name"] == mimic["joint"] and "mimic" not in j for j in tree):
            raise ValueError(f"tree: joint {joint['name']}: mimics {mimic['joint']!r}, which is not a "
                             "joint with its own coordinate")


def n_dof(tree):
    """The number of joint coordinates (mimic joints have none, a floating joint 6)."""
    return sum(len(_coordinate_names(joint)) for joint in tree)


def _coordinate_names(joint):
    """The names of a row's coordinates: none (mimic), q_<name> or six (floating)."""
    if "mimic" in joint:
        return []
    if joint["type"] == "floating":
        return [f"q_{joint['name']}_{c}" for c in FLOATING]
    return [f"q_{joint['name']}"]


def _vector(frame, xyz):
    x, y, z = (sp.Float(float(c)) if c else 0 for c in xyz)
    return x * frame.x + y * frame.y + z * frame.z


def _unit(axis):
    """The axis as numbers of norm 1 (exact for the coordinate axes: sympy keeps cos q, sin q)."""
    values = [float(a) for a in axis]
    norm = sum(a * a for a in values) ** 0.5
    if sorted(abs(a) for a in values) == [0.0, 0.0, norm]:
        return [int(round(a / norm)) for a in values]
    return [a / norm for a in values]


def rpy_matrix(rpy):
    """URDF's rotation (3, 3) of roll, pitch, yaw: Rz(yaw) Ry(pitch) Rx(roll), the columns the
    rotated frame's axes in the parent's frame."""
    r, p, y = (float(a) for a in rpy)
    cr, sr, cp, sp_, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    return np.array([[cy * cp, cy * sp_ * sr - sy * cr, cy * sp_ * cr + sy * sr],
                     [sy * cp, sy * sp_ * sr + cy * cr, sy * sp_ * cr - cy * sr],
                     [-sp_, cp * sr, cp * cr]])


#: entries of a rotation or an inertia this close to 0 (relative) or to +-1 are those numbers:
#: cos(pi/2) in floating point is 6e-17, and a term multiplied by it is kept by sympy
SNAP = 1e-14


def snapped(values, scale=1.0):
    """``values`` with entries within SNAP * scale of 0, 1 or -1 set to them (exactly)."""
    out = np.array(values, dtype=float)
    for target in (0.0, 1.0, -1.0):
        out[np.abs(out - target) < SNAP * scale] = target
    return out


def _rotation(rpy):
    """URDF's rotation matrix of rpy (sympy, columns the turned axes), entries within SNAP of
    0 or +-1 made exact."""
    return sp.Matrix([[int(x) if x in (0.0, 1.0, -1.0) else sp.Float(x) for x in row]
                      for row in snapped(rpy_matrix(rpy))])


def tree_bodies(tree, q=None):
    """(N, O, q, bodies): the base frame N (z up), the fixed base point O, the joint coordinates
    (``me.dynamicsymbols`` named after the joints unless given; none for a mimic joint) and one
    RigidBody per joint."""
    import sympy.physics.mechanics as me
    check_tree(tree)
    names = [name for joint in tree for name in _coordinate_names(joint)]
    if q is None:
        q = list(me.dynamicsymbols(" ".join(names), seq=True)) if names else []
    coordinate, k = {}, 0
    for joint in tree:
        count = len(_coordinate_names(joint))
        if count:
            coordinate[joint["name"]] = q[k] if joint["type"] != "floating" else q[k:k + count]
        k += count
    for joint in tree:
        if "mimic" in joint:
            mimic = joint["mimic"]
            coordinate[joint["name"]] = (sp.Float(float(mimic.get("multiplier", 1))) * coordinate[mimic["joint"]]
                                         + sp.Float(float(mimic.get("offset", 0))))
    N = me.ReferenceFrame("N")
    O = me.Point("O")
    O.set_vel(N, 0)
    frames, origins, bodies = [], [], []
    for i, joint in enumerate(tree):
        name, qi = joint["name"], coordinate[joint["name"]]
        parent = joint["parent"]
        P, Po = (N, O) if parent < 0 else (frames[parent], origins[parent])
        J = Po.locatenew(f"J_{name}", _vector(P, joint.get("origin", (0, 0, 0))))   # fixed in P
        if joint["type"] == "floating":            # moved by x, y, z in N, turned by three angles
            x, y, z, a, b, c = qi
            B = N.orientnew(f"B_{name}", "Body", [a, b, c], "XYZ")
            Bo = J.locatenew(f"Bo_{name}", x * N.x + y * N.y + z * N.z)
            G = Bo.locatenew(f"G_{name}", _vector(B, joint["com"]))
            ixx, iyy, izz, ixy, iyz, izx = (float(c) for c in joint["inertia"])
            bodies.append(me.RigidBody(name, G, B, float(joint["mass"]), (me.inertia(B, ixx, iyy, izz, ixy, iyz, izx), G)))
            frames.append(B)
            origins.append(Bo)
            continue
        if any(float(a) for a in joint.get("rpy", (0, 0, 0))):
            P = P.orientnew(f"F_{name}", "DCM", _rotation(joint["rpy"]))   # the joint frame
        axis = _vector(P, _unit(joint["axis"]))
        if joint["type"] == "revolute":
            B = P.orientnew(f"B_{name}", "Axis", [qi, axis])
            Bo = J
        else:                                                          # slides along the axis
            B = P.orientnew(f"B_{name}", "Axis", [0, axis])
            Bo = J.locatenew(f"Bo_{name}", qi * axis)
        G = Bo.locatenew(f"G_{name}", _vector(B, joint["com"]))
        ixx, iyy, izz, ixy, iyz, izx = (float(c) for c in joint["inertia"])
        inertia = me.inertia(B, ixx, iyy, izz, ixy, iyz, izx)
        bodies.append(me.RigidBody(name, G, B, float(joint["mass"]), (inertia, G)))
        frames.append(B)
        origins.append(Bo)
    return N, O, q, bodies


def model_from_tree(name, tree, g=9.81, description=None, limits=False, restitution=0.0):
    """The lagrange_gen Model of a tree: T = lg.kinetic_energy(N, bodies), V = gravity, the one
    parameter g (default ``g``). limits=True: the "limits" (lower, upper) of each joint with a
    coordinate are two contacts, q - lower >= 0 and upper - q >= 0 (Newton's ``restitution``)."""
    from .contacts import Contact
    g_sym = parameters("g", defaults=(float(g),))
    N, O, q, bodies = tree_bodies(tree)
    T = kinetic_energy(N, bodies)
    V = gravity_potential(N, -g_sym * N.z, bodies)
    contacts = []
    if limits:
        of_name = dict(zip((name for joint in tree for name in _coordinate_names(joint)), q))
        for joint in tree:
            qi = of_name.get(f"q_{joint['name']}")
            if "limits" in joint and "mimic" not in joint and qi is not None:
                lower, upper = (sp.Float(float(x)) for x in joint["limits"])
                contacts += [Contact(qi - lower, restitution, name=f"{joint['name']}_lower"),
                             Contact(upper - qi, restitution, name=f"{joint['name']}_upper")]
    return Model(name, coords=q, T=T, V=V, contacts=contacts,
                 description=description or f"{n_dof(tree)}-joint tree, mechanics bodies, gravity -g z")
