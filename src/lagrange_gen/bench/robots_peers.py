"""Pinocchio (the ``pin`` package, ``peers`` extra) on the same kinematic trees as our models.

``pinocchio_model(TREE)`` builds a ``pin.Model`` joint by joint from the table of
lagrange_gen.model.joint_tree: placement = (identity rotation, origin) in the parent joint's
frame, RX/RY/RZ (PX/PY/PZ) for a coordinate axis, RevoluteUnaligned (PrismaticUnaligned)
otherwise, ``pin.Inertia(mass, com, I)`` with I the full tensor about the com in the body frame,
gravity (0, 0, -g). The helpers return numpy arrays (copies: Pinocchio reuses its Data):

    peer = pinocchio_model(TREE, g=9.81)     # .model, .data: pin.Model, pin.Data
    H = crba(peer, q)                        # full symmetric mass matrix
    qdd = aba(peer, q, v, tau)
    tau = rnea(peer, q, v, a)
    dqdd_dq, dqdd_dv = aba_derivatives(peer, q, v, tau)

Pinocchio's joints are added depth first (what its algorithms need); vectors go in and come out
in the tree's joint order.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["available", "pinocchio_model", "PinocchioTree", "crba", "aba", "rnea", "aba_derivatives",
           "pinocchio_urdf", "PinocchioUrdf",
           "depth_first"]


def available():
    import importlib.util
    return importlib.util.find_spec("pinocchio") is not None


def _pin():
    import pinocchio as pin
    return pin


def _joint_model(pin, kind, axis):
    a = np.asarray(axis, dtype=float)
    a = a / np.linalg.norm(a)
    for k, letter in enumerate("XYZ"):
        e = np.zeros(3)
        e[k] = 1.0
        if np.array_equal(a, e):
            return getattr(pin, f"JointModel{'R' if kind == 'revolute' else 'P'}{letter}")()
    if kind == "revolute":
        return pin.JointModelRevoluteUnaligned(float(a[0]), float(a[1]), float(a[2]))
    return pin.JointModelPrismaticUnaligned(float(a[0]), float(a[1]), float(a[2]))


def inertia_matrix(ixx, iyy, izz, ixy, iyz, izx):
    """The 3x3 tensor of ``me.inertia(B, ixx, iyy, izz, ixy, iyz, izx)`` (entries, not
    products of inertia with a minus sign)."""
    return np.array([[ixx, ixy, izx], [ixy, iyy, iyz], [izx, iyz, izz]], dtype=float)


def depth_first(tree):
    """Joint indices of the tree in depth-first order (children in table order)."""
    children = {i: [] for i in range(-1, len(tree))}
    for i, joint in enumerate(tree):
        children[int(joint["parent"])].append(i)
    order, stack = [], list(reversed(children[-1]))
    while stack:
        i = stack.pop()
        order.append(i)
        stack.extend(reversed(children[i]))
    return order


@dataclass
class PinocchioTree:
    """A pin.Model of a tree, its Data, and ``order``: Pinocchio's joint k is the tree's joint
    order[k]. The methods take and return vectors in the tree's order."""

    model: object
    data: object
    order: list

    def to_pin(self, x):
        return np.asarray(x, dtype=float)[self.order]

    def from_pin(self, x):
        out = np.empty_like(x)
        out[self.order] = x
        return out

    def from_pin_matrix(self, A):
        out = np.empty_like(A)
        out[np.ix_(self.order, self.order)] = A
        return out

    def crba(self, q):
        """The mass matrix, both triangles (Pinocchio fills the upper one)."""
        M = np.array(_pin().crba(self.model, self.data, self.to_pin(q)))
        return self.from_pin_matrix(np.triu(M) + np.triu(M, 1).T)

    def aba(self, q, v, tau):
        return self.from_pin(np.array(_pin().aba(self.model, self.data, self.to_pin(q),
                                                 self.to_pin(v), self.to_pin(tau))))

    def rnea(self, q, v, a):
        return self.from_pin(np.array(_pin().rnea(self.model, self.data, self.to_pin(q),
                                                  self.to_pin(v), self.to_pin(a))))

    def aba_derivatives(self, q, v, tau):
        """(d qdd/dq, d qdd/dv) from ``pin.computeABADerivatives``."""
        out = _pin().computeABADerivatives(self.model, self.data, self.to_pin(q), self.to_pin(v),
                                            self.to_pin(tau))
        return self.from_pin_matrix(np.array(out[0])), self.from_pin_matrix(np.array(out[1]))


def pinocchio_model(tree, g=9.81):
    """PinocchioTree of the tree, gravity (0, 0, -g).

    The joints are added depth first: Pinocchio's crba and derivative algorithms assume every
    subtree occupies a contiguous range of joint indices (its URDF parser adds them so) and,
    given another order (two chains from the base added alternately), silently return a wrong
    mass matrix while rnea and aba stay right."""
    pin = _pin()
    model = pin.Model()
    order = depth_first(tree)
    ids = {}
    for i in order:
        joint = tree[i]
        parent = 0 if joint["parent"] < 0 else ids[joint["parent"]]
        placement = pin.SE3(np.eye(3), np.asarray(joint["origin"], dtype=float))
        jid = model.addJoint(parent, _joint_model(pin, joint["type"], joint["axis"]), placement,
                             str(joint["name"]))
        inertia = pin.Inertia(float(joint["mass"]), np.asarray(joint["com"], dtype=float),
                              inertia_matrix(*(float(c) for c in joint["inertia"])))
        model.appendBodyToJoint(jid, inertia, pin.SE3.Identity())
        ids[i] = jid
    model.gravity.linear = np.array([0.0, 0.0, -float(g)])
    return PinocchioTree(model, model.createData(), order)


def crba(peer, q):
    return peer.crba(q)


def aba(peer, q, v, tau):
    return peer.aba(q, v, tau)


def rnea(peer, q, v, a):
    return peer.rnea(q, v, a)


def aba_derivatives(peer, q, v, tau):
    return peer.aba_derivatives(q, v, tau)


@dataclass
class PinocchioUrdf:
    """A pin.Model read by Pinocchio's own URDF parser (fixed base), its Data, and the layout of
    its q and v: ``columns[k]`` is the v index of our coordinate k, ``continuous`` the joints
    whose q is (cos, sin) (RUBX/Y/Z: (q index, v index)). The methods take and return vectors
    in our coordinate order, q as joint angles."""

    model: object
    data: object
    names: list
    columns: list
    continuous: list

    def q_pin(self, q):
        pin = _pin()
        v = np.zeros(self.model.nv)
        v[self.columns] = q
        out = pin.neutral(self.model)
        plain = np.ones(self.model.nv, dtype=bool)
        for qi, vi in self.continuous:
            out[qi], out[qi + 1] = np.cos(v[vi]), np.sin(v[vi])
            plain[vi] = False
        for joint in self.model.joints[1:]:
            if joint.nv and joint.nq == joint.nv and plain[joint.idx_v]:
                out[joint.idx_q:joint.idx_q + joint.nq] = v[joint.idx_v:joint.idx_v + joint.nv]
        return out

    def v_pin(self, x):
        out = np.zeros(self.model.nv)
        out[self.columns] = x
        return out

    def crba(self, q):
        M = np.array(_pin().crba(self.model, self.data, self.q_pin(q)))
        M = np.triu(M) + np.triu(M, 1).T
        return M[np.ix_(self.columns, self.columns)]

    def aba(self, q, v, tau):
        """pin.aba; with mimic joints (which Pinocchio's aba refuses) crba's M solved for
        tau - rnea(q, v, 0)."""
        if any(j.nv == 0 for j in self.model.joints[1:]):
            return np.linalg.solve(self.crba(q), np.asarray(tau) - self.rnea(q, v, np.zeros(len(self.columns))))
        return np.array(_pin().aba(self.model, self.data, self.q_pin(q), self.v_pin(v), self.v_pin(tau)))[self.columns]

    def rnea(self, q, v, a):
        return np.array(_pin().rnea(self.model, self.data, self.q_pin(q), self.v_pin(v), self.v_pin(a)))[self.columns]


def pinocchio_urdf(path, coords, mimic=True, g=9.81, floating=False):
    """PinocchioUrdf of the URDF file ``path`` (fixed base, gravity (0, 0, -g)); ``coords``: our
    coordinate names (``q_<joint>``, the joint made an identifier), matched to Pinocchio's joints
    by name. mimic: Pinocchio's mimic joints (pin >= 3.4), else every joint its own coordinate.
    floating: the root joint a composite of PX, PY, PZ, RX, RY, RZ (our floating row's position
    and angles about the body's x, then y, then z), matched to the first six of ``coords``."""
    import re
    pin = _pin()
    if floating:
        root = pin.JointModelComposite()
        for kind in ("PX", "PY", "PZ", "RX", "RY", "RZ"):
            root.addJoint(getattr(pin, f"JointModel{kind}")())
        model = pin.buildModelFromUrdf(str(path), root, mimic=mimic)
    else:
        model = pin.buildModelFromUrdf(str(path), mimic=mimic)
    model.gravity.linear = np.array([0.0, 0.0, -float(g)])
    by_name, continuous, names = {}, [], []
    for joint, name in zip(model.joints[1:], list(model.names)[1:]):
        if joint.nv == 6 and floating and joint.idx_v == 0:
            for k in range(6):
                by_name[coords[k]] = k
                names.append(coords[k])
            continue
        if joint.nv == 0:
            continue
        ident = "q_" + re.sub(r"\W", "_", name)
        by_name[ident] = joint.idx_v
        names.append(ident)
        if joint.nq == 2 and joint.nv == 1:
            continuous.append((joint.idx_q, joint.idx_v))
    missing = [c for c in coords if c not in by_name]
    if missing or len(coords) != model.nv:
        raise ValueError(f"{path}: Pinocchio's joints {names} do not match ours {list(coords)}")
    return PinocchioUrdf(model, model.createData(), names, [by_name[c] for c in coords], continuous)
