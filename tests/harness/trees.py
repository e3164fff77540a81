"""Random spatial trees of bodies written the ways users write them with sympy.physics.mechanics,
and a reference for them that never goes through lagrange_gen.model.bodies or derive/.

A drawn tree (DrawnTree) is a list of BodySpec: parent, joint kind (revolute or prismatic), the
way the joint's frame is written (``orientnew(..., "Axis")``, ``orient_axis``, a body-fixed or a
space-fixed rotation sequence with the coordinate as one of the angles, a constant pre-rotation
then an axis), random joint offsets and centres of mass, a RigidBody with a full inertia tensor
(about its mass centre or about the joint) or a Particle, velocities found by sympy from the
positions or set with v2pt_theory / v1pt_theory, gravity as ``lg.gravity_potential`` or as
``me.Force`` on each mass centre, masses as numbers or as parameters. ``style="table"`` draws a
joint table (analysis.random_trees.random_tree) built by model.joint_tree.tree_bodies instead.

TreeReference: Lagrange's equations for the same mechanics objects, from sympy's own kinematics
(``N.dcm(B)``, ``point.pos_from(O)``) lambdified, with every derivative of the energy exact to
rounding: T(q, qd) = sum m |dc/dq qd|^2 / 2 + w^T I w / 2 (w from R^T dR/dt, dR/dt and dc/dq
differentiated by sympy), H from the polarization of T (T is quadratic in qd), dT/dq and
d(H qd)/dq qd by complex steps (f'(x) = Im f(x + ih)/h, no cancellation). The expanded
symbolic route (sympy's kinetic_energy, differentiated twice) costs 20 s to minutes of sympy
per 3-body tree with random axes, too slow to draw trees by the dozen.

Shapes: n coordinates; q, qd (n,); H (n, n); vectors (n,).
"""

from __future__ import annotations

import itertools
import types
from dataclasses import dataclass

import numpy as np
import sympy as sp
from hypothesis import strategies as st

import lagrange_gen as lg

#: ways a revolute joint's frame is written (see BodySpec)
ROTATIONS = ("orientnew_axis", "orient_axis", "body_fixed", "space_fixed", "pre_rotated")
ANGLE_BOX, SLIDE_BOX, SPEED_SCALE = (-2.0, 2.0), (-0.4, 0.4), 1.5
_names = itertools.count()
_STEP = 1e-30                      # complex step: exact to rounding for any step this small


@dataclass
class BodySpec:
    """One body on one joint. parent: index of an earlier body or -1 (the base); kind:
    "revolute" or "prismatic"; rotation: one of ROTATIONS (revolute); angles: the two constant
    angles of a body-fixed, space-fixed or pre-rotated joint frame, or the unit axis (3,) for
    orientnew_axis / orient_axis / prismatic; origin: the joint in the parent's frame (3,); com:
    the mass centre in this body's frame (3,); mass; inertia (ixx, iyy, izz, ixy, iyz, izx) about
    the mass centre or None for a Particle; inertia_about_joint: give the RigidBody its inertia
    about the joint point (parallel axis) instead; mass_parameter: the mass is a parameter."""

    parent: int
    kind: str
    rotation: str
    angles: tuple
    origin: tuple
    com: tuple
    mass: float
    inertia: tuple | None
    inertia_about_joint: bool = False
    mass_parameter: bool = False


@dataclass
class DrawnTree:
    """A drawn spatial tree: bodies (BodySpec), or a joint table (style "table"); how the
    velocities are given (velocities: "positions" or "v2pt") and gravity ("potential" or "force")."""

    name: str
    bodies: list
    velocities: str = "positions"
    gravity: str = "potential"
    table: list | None = None

    @property
    def n(self):
        return len(self.table) if self.table is not None else len(self.bodies)

    @property
    def prismatic(self):
        """(n,) bool: which coordinates are slides (sampled in SLIDE_BOX, the others in ANGLE_BOX)."""
        kinds = [j["type"] for j in self.table] if self.table is not None else [b.kind for b in self.bodies]
        return np.array([k == "prismatic" for k in kinds])

    def mechanics(self):
        """(N, O, q, bodies, g, params): the base frame, the fixed base point, the coordinates
        (dynamicsymbols), the mechanics bodies, the gravity parameter and every Parameter."""
        g = lg.parameters("g", defaults=(9.81,))
        if self.table is not None:
            from lagrange_gen.model.joint_tree import tree_bodies
            N, O, q, bodies = tree_bodies(self.table)
            return N, O, q, bodies, g, [g]
        return _build_bodies(self, g)

    def build(self):
        """A fresh lagrange_gen Model of the tree: T = lg.kinetic_energy(N, bodies), gravity
        -g N.z as V or as forces."""
        import sympy.physics.mechanics as me
        N, O, q, bodies, g, _ = self.mechanics()
        T = lg.kinetic_energy(N, bodies)
        if self.gravity == "potential":
            return lg.Model(self.name, coords=q, T=T, V=lg.gravity_potential(N, -g * N.z, bodies))
        forces = [me.Force(b.masscenter, -b.mass * g * N.z) for b in bodies]
        return lg.Model(self.name, coords=q, T=T, forces=forces, frame=N)


def _vec(frame, xyz):
    return sum((sp.Float(c) * e for c, e in zip(xyz, (frame.x, frame.y, frame.z)) if c), sp.S.Zero * frame.x)


def _build_bodies(drawn, g):
    import sympy.physics.mechanics as me
    tag = drawn.name
    q = list(me.dynamicsymbols(" ".join(f"q{i}_{tag}" for i in range(drawn.n)), seq=True))
    N = me.ReferenceFrame("N")
    O = me.Point("O")
    O.set_vel(N, 0)
    frames, origins, bodies, params = [], [], [], [g]
    for i, b in enumerate(drawn.bodies):
        P, Po = (N, O) if b.parent < 0 else (frames[b.parent], origins[b.parent])
        J = Po.locatenew(f"J{i}", _vec(P, b.origin))
        if b.kind == "prismatic":
            B, Bo = P, J.locatenew(f"S{i}", q[i] * _vec(P, b.angles))
        else:
            B, Bo = _rotated(P, i, b, q[i]), J
        if drawn.velocities == "v2pt":
            J.v2pt_theory(Po, N, P)                 # both fixed in P
            if b.kind == "prismatic":               # slides along the axis in P
                Bo.set_vel(P, q[i].diff(me.dynamicsymbols._t) * _vec(P, b.angles))
                Bo.v1pt_theory(J, N, P)
        G = Bo.locatenew(f"G{i}", _vec(B, b.com))
        if drawn.velocities == "v2pt":
            G.v2pt_theory(Bo, N, B)
        mass = sp.Float(b.mass)
        if b.mass_parameter:
            mass = lg.parameters(f"m{i}", defaults=(b.mass,))
            params.append(mass)
        if b.inertia is None:
            bodies.append(me.Particle(f"P{i}", G, mass))
        else:
            central = me.inertia(B, *(sp.Float(c) for c in b.inertia))
            if b.inertia_about_joint:
                about_joint = central + me.inertia_of_point_mass(mass, G.pos_from(Bo), B)
                bodies.append(me.RigidBody(f"B{i}", G, B, mass, (about_joint, Bo)))
            else:
                bodies.append(me.RigidBody(f"B{i}", G, B, mass, (central, G)))
        frames.append(B)
        origins.append(Bo)
    return N, O, q, bodies, g, params


def _rotated(P, i, b, qi):
    """Body i's frame turned by qi from P, written the way BodySpec.rotation says."""
    import sympy.physics.mechanics as me
    a, c = (sp.Float(x) for x in b.angles[:2]) if b.rotation in ("body_fixed", "space_fixed", "pre_rotated") else (0, 0)
    if b.rotation == "orientnew_axis":
        return P.orientnew(f"B{i}", "Axis", [qi, _vec(P, b.angles)])
    if b.rotation == "orient_axis":
        B = me.ReferenceFrame(f"B{i}")
        B.orient_axis(P, _vec(P, b.angles), qi)
        return B
    if b.rotation == "body_fixed":                       # about x, then the new y, then the new z
        B = me.ReferenceFrame(f"B{i}")
        B.orient_body_fixed(P, (a, c, qi), "XYZ")
        return B
    if b.rotation == "space_fixed":                      # about P.x by qi, then P.y, then P.z
        return P.orientnew(f"B{i}", "Space", [qi, a, c], "XYZ")
    C = P.orientnew(f"C{i}", "Body", [a, c, sp.Float(0.3)], "ZXZ")   # constant, then about C.z
    return C.orientnew(f"B{i}", "Axis", [qi, C.z])


# ------------------------------------------------------------------------------------ strategies


def _floats(lo, hi):
    return st.floats(lo, hi, allow_nan=False, allow_infinity=False).map(lambda x: round(x, 6))


@st.composite
def unit_vectors(draw):
    for _ in range(20):
        v = np.array([draw(_floats(-1, 1)) for _ in range(3)])
        if np.linalg.norm(v) > 0.3:
            return tuple(round(float(x), 9) for x in v / np.linalg.norm(v))
    return (0.0, 0.0, 1.0)


@st.composite
def inertia_tensors(draw):
    """(ixx, iyy, izz, ixy, iyz, izx) of R diag(d) R^T, principal moments obeying the triangle
    inequality (a physical rigid body)."""
    d = [draw(_floats(0.02, 0.2)), draw(_floats(0.02, 0.2))]
    d.append(draw(_floats(abs(d[0] - d[1]) + 0.005, d[0] + d[1] - 0.005)))
    seed = draw(st.integers(0, 2**31))
    R, _ = np.linalg.qr(np.random.default_rng(seed).normal(size=(3, 3)))
    I = R @ np.diag(d) @ R.T
    return tuple(round(float(x), 12) for x in (I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[1, 2], I[2, 0]))


def _prismatic_run(specs, parent):
    """Slides in a row ending at ``parent`` (four in a row would leave H singular in 3D)."""
    run = 0
    while parent >= 0 and specs[parent].kind == "prismatic":
        run, parent = run + 1, specs[parent].parent
    return run


@st.composite
def body_specs(draw, specs):
    """The next BodySpec of a tree whose earlier bodies are ``specs``."""
    parent = draw(st.integers(-1, len(specs) - 1))
    kind = "prismatic" if _prismatic_run(specs, parent) < 2 and draw(st.integers(0, 3)) == 0 else "revolute"
    rotation = draw(st.sampled_from(ROTATIONS)) if kind == "revolute" else "none"
    if kind == "prismatic" or rotation in ("orientnew_axis", "orient_axis"):
        angles = draw(unit_vectors())
    else:
        angles = (draw(_floats(-3, 3)), draw(_floats(-3, 3)))
    origin = tuple(draw(_floats(-0.5, 0.5)) for _ in range(3))
    com = tuple(draw(_floats(-0.3, 0.3)) for _ in range(3))
    particle = draw(st.integers(0, 4)) == 0
    if particle:
        # a point mass on its revolute axis would add nothing to H's diagonal: keep it 0.15 off
        com = tuple(c + 0.15 * s for c, s in zip(com, _off_axis(rotation, angles)))
    return BodySpec(parent=parent, kind=kind, rotation=rotation, angles=angles, origin=origin, com=com,
                    mass=draw(_floats(0.5, 3.0)), inertia=None if particle else draw(inertia_tensors()),
                    inertia_about_joint=not particle and draw(st.integers(0, 3)) == 0,
                    mass_parameter=draw(st.integers(0, 4)) == 0)


def _off_axis(rotation, angles):
    """A unit vector perpendicular to the joint's axis in the body's frame (revolute), where
    the axis is known in closed form; a fixed direction otherwise (the random com is kept too)."""
    if rotation in ("orientnew_axis", "orient_axis"):
        a = np.array(angles)
        u = np.cross(a, [1.0, 0.0, 0.0] if abs(a[0]) < 0.9 else [0.0, 1.0, 0.0])
        return tuple(u / np.linalg.norm(u))
    if rotation == "body_fixed":        # the last rotation is about the body's own z
        return (1.0, 0.0, 0.0)
    if rotation == "pre_rotated":       # about C.z, which is B.z
        return (1.0, 0.0, 0.0)
    return (0.0, 0.7071067811865476, 0.7071067811865476)   # space_fixed, prismatic: generic


@st.composite
def spatial_trees(draw, n_min=3, n_max=4, table=None):
    """A DrawnTree of n_min..n_max bodies; table: True draws a joint table (random_tree), False
    mechanics objects written directly, None either. v2pt velocities only up to 4 bodies (a
    velocity given on a moving point is taken as written out in N, which grows with depth)."""
    n = draw(st.integers(n_min, n_max))
    name = f"tree_{next(_names)}"
    if table is None:
        table = draw(st.integers(0, 3)) == 0
    if table:
        from lagrange_gen.analysis.random_trees import random_tree
        seed = draw(st.integers(0, 2**31))
        tree = random_tree(np.random.default_rng(seed), n, prismatic=draw(st.sampled_from([0.0, 0.3])),
                           aligned=draw(st.sampled_from([0.0, 0.5])))
        return DrawnTree(name, [], table=tree)
    specs = []
    for _ in range(n):
        specs.append(draw(body_specs(specs)))
    velocities = "v2pt" if n <= 4 and draw(st.integers(0, 2)) == 0 else "positions"
    return DrawnTree(name, specs, velocities=velocities, gravity=draw(st.sampled_from(["potential", "force"])))


def sample_states(drawn, params, rng, count):
    """``count`` (q (n,), qd (n,), {parameter: value}) triples; the first at the default
    parameters, the others with each scaled by a factor in [0.7, 1.4]."""
    out = []
    for i in range(count):
        q = np.where(drawn.prismatic, rng.uniform(*SLIDE_BOX, drawn.n), rng.uniform(*ANGLE_BOX, drawn.n))
        values = {p.name: p.default * (1.0 if i == 0 else rng.uniform(0.7, 1.4)) for p in params}
        out.append((q, rng.uniform(-SPEED_SCALE, SPEED_SCALE, drawn.n), values))
    return out


# ------------------------------------------------------------------------------------ reference


class TreeReference:
    """Lagrange's equations of a DrawnTree's mechanics objects, evaluated exactly to rounding
    (see the module docstring). ``value(name, state)`` with the names of harness.reference
    (H, rhs, E, momentum_rate, tau_id, gravity, bias, and the zero quantities of a model without
    forces, constraints or elements) so check.check_kernels can use it."""

    def __init__(self, drawn):
        import sympy.physics.mechanics as me
        N, O, q, bodies, g, params = drawn.mechanics()
        n = len(q)
        self.n, self.m, self.ne = n, 0, 0
        self.drawn = types.SimpleNamespace(events=[])
        self.params = params
        Q, V = sp.symbols(f"ref_q0:{n}", real=True), sp.symbols(f"ref_v0:{n}", real=True)
        plain = {x: s for x, s in zip(q, Q)}
        t = me.dynamicsymbols._t
        plain_t = {x.diff(t): s for x, s in zip(q, V)}
        args = [*Q, *V, *params]
        self._kinematics = []           # per body: (mass, I (3, 3) or None, f(q, qd, p) -> (cdot, w))
        V_total = sp.S.Zero
        for body in bodies:
            c = body.masscenter.pos_from(O).to_matrix(N).xreplace(plain)
            cdot = c.jacobian(Q) * sp.Matrix(V)
            if isinstance(body, me.RigidBody):
                B = body.frame                                     # columns: B's axes in N
                R = sp.Matrix.hstack(*(e.to_matrix(N) for e in (B.x, B.y, B.z))).xreplace(plain)
                Rdot = sum((R.diff(x) * v for x, v in zip(Q, V)), sp.zeros(3, 3))
                W = R.T * Rdot                                     # skew(w), w in body components
                w = sp.Matrix([W[2, 1], W[0, 2], W[1, 0]])
                I = body.central_inertia.to_matrix(body.frame)
                exprs, inertia = [*cdot, *w], sp.lambdify(params, I)
            else:
                exprs, inertia = list(cdot), None
            # numpy functions handle the complex arguments of the complex steps
            self._kinematics.append((sp.lambdify(params, body.mass), inertia,
                                     sp.lambdify(args, exprs, modules="numpy", cse=True)))
            V_total += body.mass * g * c[2]
        self._V = sp.lambdify([*Q, *params], V_total, modules="numpy")
        self._memo = {}

    # -- the energies as numeric functions (complex arguments welcome) -------------------
    def T(self, q, qd, p):
        total = 0.0
        for mass, inertia, kin in self._kinematics:
            values = kin(*q, *qd, *p)
            cdot = np.array(values[:3])
            total = total + mass(*p) * (cdot @ cdot) / 2
            if inertia is not None:
                w = np.array(values[3:])
                total = total + w @ (np.array(inertia(*p), dtype=float) @ w) / 2
        return total

    def V(self, q, p):
        return self._V(*q, *p)

    # -- Lagrange's equations ---------------------------------------------------------------
    def H(self, q, p):
        """d2T/dqd2 by polarization: T(q, .) is a quadratic form."""
        n, E = self.n, np.eye(self.n)
        diag = [self.T(q, E[i], p) for i in range(n)]
        H = np.empty((n, n))
        for i in range(n):
            H[i, i] = 2 * diag[i]
            for j in range(i):
                H[i, j] = H[j, i] = self.T(q, E[i] + E[j], p) - diag[i] - diag[j]
        return np.real(H)

    def _dq(self, f, q):
        """(n,) gradient of a real-analytic scalar f(q) by complex steps."""
        return np.array([np.imag(f(q + 1j * _STEP * e)) / _STEP for e in np.eye(self.n)])

    def quantities(self, q, qd, p):
        """{H, rhs, E, momentum_rate, gravity}: H qdd = rhs; momentum_rate = dT/dq - dV/dq."""
        H = self.H(q, p)
        dT_dq = self._dq(lambda x: self.T(x, qd, p), q)
        gravity = self._dq(lambda x: self.V(x, p), q)
        # d/dq (H qd) qd: H(q + i h qd) qd, H by polarization at a complex q
        dHqd = np.imag(self._H_complex(q + 1j * _STEP * qd, p) @ qd) / _STEP
        E = float(np.real(self.T(q, qd, p) + self.V(q, p)))
        return {"H": H, "rhs": dT_dq - dHqd - gravity, "E": E, "momentum_rate": dT_dq - gravity,
                "gravity": gravity}

    def _H_complex(self, q, p):
        n, E = self.n, np.eye(self.n)
        diag = [self.T(q, E[i], p) for i in range(n)]
        H = np.empty((n, n), dtype=complex)
        for i in range(n):
            H[i, i] = 2 * diag[i]
            for j in range(i):
                H[i, j] = H[j, i] = self.T(q, E[i] + E[j], p) - diag[i] - diag[j]
        return H

    def value(self, name, state):
        """The quantity ``name`` at a harness State (q, qd, params by name, w = the qdd given
        to inverse_dynamics)."""
        n = self.n
        p = [state.params[s.name] for s in self.params]
        zeros = {"power": np.zeros(2 * n + 2), "b": np.zeros(n), "db": np.zeros((n, n)), "s": np.zeros(0),
                 "G": np.zeros((0, n)), "coef": np.zeros((0, 3)), "hess_w": np.zeros((n, n)),
                 "events": np.zeros(0), "Phi": np.zeros(0), "J": np.zeros((0, n)), "gamma": np.zeros(0),
                 "Phi_t": np.zeros(0), "dJw_dq": np.zeros((0, n)), "dJTlam_dq": np.zeros((n, n))}
        if name in zeros:
            return zeros[name]
        key = (tuple(state.q), tuple(state.qd), tuple(p))
        if self._memo.get("key") != key:
            self._memo = {"key": key, "values": self.quantities(state.q, state.qd, p)}
        values = dict(self._memo["values"])
        values["tau_id"] = values["H"] @ state.w - values["rhs"]
        values["bias"] = -values["rhs"]
        return values[name]
