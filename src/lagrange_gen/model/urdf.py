"""A robot's URDF read into the joint table of model/joint_tree.py, and from there into a Model.

    model = lg.from_urdf("ur5.urdf")                     # a Model, like any model file's
    tree = urdf_tree("ur5.urdf")                         # the joint table (list of dicts)
    text = model_file_text("ur5.urdf")                   # a model file holding that table

What each URDF element becomes:

* a moving joint (revolute, continuous, prismatic) is one row of the table: its ``origin``
  xyz and ``rpy`` (the joint frame in the parent's), ``axis`` in the joint frame, and the mass,
  com and central inertia of its child link in the joint frame (the inertial origin's rpy
  turns the inertia: I_link = R I R^T). A continuous joint is a revolute one (its limits are
  not read);
* a fixed joint is merged into the link above it: the child's mass, mass centre and inertia
  are added to the parent's (parallel axis theorem), and the joints below it are moved to the
  parent's frame (origin and rotation composed). Under the root link the merged links move
  with nothing and are dropped (a fixed base);
* a ``mimic`` joint (q = multiplier * q_other + offset) has no coordinate of its own: its row
  keeps ``"mimic": {"joint": other, "multiplier": m, "offset": c}``;
* a link without ``<inertial>`` has no mass (as the URDF specification says); a moving joint
  whose child and every link below it has no mass is refused (its column of the mass matrix
  would be zero);
* visuals, collisions (``package://`` meshes), transmissions, gazebo and other elements are
  not read; neither are ``<dynamics>`` damping and friction. A ``<limit>``'s lower and upper
  (revolute, prismatic) are kept as the row's ``"limits"``: two contacts when asked for.

Coordinates are named after the joints (made identifiers: ``q_<joint>``) and ordered as
Pinocchio's URDF parser orders them: depth first from the root link, the child joints of a
link in the order of their names (urdfdom keeps the joints in a map sorted by name, and
Pinocchio walks that).

The parser is the standard library's XML parser (expat, through xml.parsers.expat): it gives
line numbers for errors and needs no dependency; a URDF's kinematic and inertial elements are a
few attributes, and the meshes that libraries such as yourdfpy load (with trimesh, lxml) are
not needed here. Bad input is one ModelError line naming the file, the line and the element.
"""

from __future__ import annotations

import keyword
import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import ModelError
from .joint_tree import model_from_tree, n_dof, rpy_matrix, snapped

__all__ = ["from_urdf", "urdf_tree", "model_file_text", "read_urdf", "matrix_rpy", "make_identifier"]

MOVING = ("revolute", "continuous", "prismatic")
SUPPORTED = MOVING + ("fixed",)


@dataclass
class Element:
    """One URDF element: tag, attributes, line, children."""

    tag: str
    attrs: dict
    line: int
    children: list = field(default_factory=list)

    def find(self, tag):
        return next((c for c in self.children if c.tag == tag), None)

    def findall(self, tag):
        return [c for c in self.children if c.tag == tag]


@dataclass
class Inertial:
    """Mass (kg), mass centre (3,) and central inertia (3, 3) in the link's frame."""

    mass: float
    com: np.ndarray
    inertia: np.ndarray


@dataclass
class Joint:
    name: str
    kind: str
    parent: str
    child: str
    xyz: np.ndarray
    rpy: np.ndarray
    axis: np.ndarray
    mimic: tuple | None          # (joint name, multiplier, offset, line)
    line: int
    limits: tuple | None = None  # (lower, upper) of a revolute or prismatic joint's <limit>


@dataclass
class Robot:
    """The kinematic and inertial content of a URDF: links {name: Inertial or None}, joints
    in file order, the line of each link."""

    name: str
    path: str
    links: dict
    link_lines: dict
    joints: list


# ------------------------------------------------------------------------------- parsing


def _parse_xml(path, text):
    """The root Element of ``text``; ModelError with the line of a malformed document."""
    from xml.parsers import expat
    parser = expat.ParserCreate()
    stack, root = [], []

    def start(tag, attrs):
        element = Element(tag, dict(attrs), parser.CurrentLineNumber)
        (stack[-1].children if stack else root).append(element)
        stack.append(element)

    def end(tag):
        stack.pop()

    parser.StartElementHandler, parser.EndElementHandler = start, end
    try:
        parser.Parse(text, True)
    except expat.ExpatError as exc:
        raise ModelError(f"{path}:{exc.lineno}: malformed XML: {expat.ErrorString(exc.code)}") from None
    return root[0]


def _numbers(path, element, attribute, count, default=None):
    text = element.attrs.get(attribute) if element is not None else None
    if text is None:
        if default is None:
            where = f"<{element.tag}>" if element is not None else "an element"
            raise ModelError(f"{path}:{element.line if element is not None else '?'}: {where} "
                             f"needs the attribute {attribute}")
        return np.array(default, dtype=float)
    try:
        values = [float(x) for x in text.split()]
    except ValueError:
        values = []
    if len(values) != count or not all(math.isfinite(v) for v in values):
        raise ModelError(f"{path}:{element.line}: <{element.tag} {attribute}=\"{text}\">: "
                         f"{count} finite number{'s' if count > 1 else ''} expected")
    return np.array(values)


def _origin(path, element):
    """(xyz (3,), rpy (3,)) of the element's <origin> (zeros when it has none)."""
    origin = element.find("origin")
    if origin is None:
        return np.zeros(3), np.zeros(3)
    return _numbers(path, origin, "xyz", 3, (0, 0, 0)), _numbers(path, origin, "rpy", 3, (0, 0, 0))


def _inertial(path, link):
    inertial = link.find("inertial")
    if inertial is None:
        return None
    xyz, rpy = _origin(path, inertial)
    mass_element = inertial.find("mass")
    if mass_element is None:
        raise ModelError(f"{path}:{inertial.line}: link {link.attrs.get('name')!r}: <inertial> without <mass>")
    mass = float(_numbers(path, mass_element, "value", 1)[0])
    inertia_element = inertial.find("inertia")
    if inertia_element is None:
        raise ModelError(f"{path}:{inertial.line}: link {link.attrs.get('name')!r}: <inertial> without <inertia>")
    ixx, ixy, ixz, iyy, iyz, izz = (float(_numbers(path, inertia_element, a, 1)[0])
                                    for a in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz"))
    if mass < 0:
        raise ModelError(f"{path}:{mass_element.line}: link {link.attrs.get('name')!r}: negative mass {mass}")
    R = rpy_matrix(rpy)
    inertia = R @ np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]]) @ R.T
    return Inertial(mass, xyz, inertia)


def _joint(path, element):
    name = element.attrs.get("name")
    if not name:
        raise ModelError(f"{path}:{element.line}: <joint> without a name")
    kind = element.attrs.get("type")
    if kind not in SUPPORTED:
        extra = " (floating bases: not yet supported)" if kind == "floating" else ""
        raise ModelError(f"{path}:{element.line}: joint {name!r}: type {kind!r} is not supported "
                         f"(one of {', '.join(SUPPORTED)}){extra}")
    links = []
    for tag in ("parent", "child"):
        sub = element.find(tag)
        if sub is None or not sub.attrs.get("link"):
            raise ModelError(f"{path}:{element.line}: joint {name!r} needs <{tag} link=\"...\"/>")
        links.append(sub.attrs["link"])
    xyz, rpy = _origin(path, element)
    axis = _numbers(path, element.find("axis"), "xyz", 3, (1, 0, 0)) if element.find("axis") is not None \
        else np.array([1.0, 0.0, 0.0])
    if kind in MOVING and float(axis @ axis) < 1e-24:
        raise ModelError(f"{path}:{element.find('axis').line}: joint {name!r}: zero axis")
    mimic = None
    mimic_element = element.find("mimic")
    if mimic_element is not None and kind in MOVING:
        other = mimic_element.attrs.get("joint")
        if not other:
            raise ModelError(f"{path}:{mimic_element.line}: joint {name!r}: <mimic> without joint=\"...\"")
        multiplier = float(_numbers(path, mimic_element, "multiplier", 1, (1,))[0])
        offset = float(_numbers(path, mimic_element, "offset", 1, (0,))[0])
        mimic = (other, multiplier, offset, mimic_element.line)
    limits = None
    limit = element.find("limit")
    if limit is not None and kind in ("revolute", "prismatic"):
        lower = float(_numbers(path, limit, "lower", 1, (0,))[0])
        upper = float(_numbers(path, limit, "upper", 1, (0,))[0])
        if lower < upper:
            limits = (lower, upper)
    return Joint(name, kind, links[0], links[1], xyz, rpy, axis, mimic, element.line, limits)


def read_urdf(path) -> Robot:
    """The links and joints of the URDF file at ``path`` (module docstring); ModelError naming
    the file and line of anything malformed."""
    path = str(path)
    try:
        text = Path(path).read_bytes()
    except OSError as exc:
        raise ModelError(f"{path}: cannot read the URDF ({exc.strerror or exc})") from None
    root = _parse_xml(path, text)
    if root.tag != "robot":
        raise ModelError(f"{path}:{root.line}: the root element is <{root.tag}>, not <robot>")
    links, lines = {}, {}
    for link in root.findall("link"):
        name = link.attrs.get("name")
        if not name:
            raise ModelError(f"{path}:{link.line}: <link> without a name")
        if name in links:
            raise ModelError(f"{path}:{link.line}: link {name!r} defined twice (first on line {lines[name]})")
        links[name], lines[name] = _inertial(path, link), link.line
    if not links:
        raise ModelError(f"{path}:{root.line}: <robot> has no <link>")
    joints, seen = [], {}
    for element in root.findall("joint"):
        joint = _joint(path, element)
        if joint.name in seen:
            raise ModelError(f"{path}:{joint.line}: joint {joint.name!r} defined twice (first on line {seen[joint.name]})")
        seen[joint.name] = joint.line
        for link in (joint.parent, joint.child):
            if link not in links:
                raise ModelError(f"{path}:{joint.line}: joint {joint.name!r}: no link named {link!r}")
        joints.append(joint)
    name = root.attrs.get("name") or Path(path).stem
    return Robot(name, path, links, lines, joints)


# ------------------------------------------------------------------------------ rotations


def matrix_rpy(R):
    """(roll, pitch, yaw) with rpy_matrix(rpy) = R to rounding, also near pitch = +-pi/2: pitch
    and yaw are read from R, then roll from Ry(pitch)^T Rz(yaw)^T R, which is a rotation about x
    whatever error yaw has there (the two angles turn about the same axis)."""
    R = np.asarray(R, dtype=float)
    pitch = math.atan2(-R[2, 0], math.hypot(R[0, 0], R[1, 0]))
    yaw = math.atan2(R[1, 0], R[0, 0])
    rest = (rpy_matrix((0, pitch, yaw))).T @ R
    roll = math.atan2(rest[2, 1], rest[1, 1])
    return np.array([roll, pitch, yaw])


# ------------------------------------------------------------------------ the joint table


def make_identifier(name, used):
    """``name`` as a Python identifier (other characters -> _), unique among ``used``."""
    ident = re.sub(r"\W", "_", name)
    if not ident or ident[0].isdigit() or keyword.iskeyword(ident):
        ident = "j_" + ident
    base, k = ident, 2
    while ident in used:
        ident, k = f"{base}_{k}", k + 1
    used.add(ident)
    return ident


def _children(robot):
    """({link: [joints below it, by name]}, root link); ModelError for a loop, a link with two
    parents or two roots."""
    path = robot.path
    parent_of = {}
    for joint in robot.joints:
        if joint.child in parent_of:
            first = parent_of[joint.child]
            raise ModelError(f"{path}:{joint.line}: joint {joint.name!r}: link {joint.child!r} already has "
                             f"the parent joint {first.name!r} (line {first.line}): a loop, not a tree")
        parent_of[joint.child] = joint
    roots = [name for name in robot.links if name not in parent_of]
    if not roots:
        link, seen = robot.joints[0].child, set()
        while link not in seen:                 # up the parents until a link comes back
            seen.add(link)
            link = parent_of[link].parent
        joint = parent_of[link]
        raise ModelError(f"{path}:{joint.line}: joint {joint.name!r} is on a loop of joints (every link has a "
                         "parent joint): not a tree")
    children = {name: [] for name in robot.links}
    for joint in robot.joints:
        children[joint.parent].append(joint)
    reached, stack = set(), [roots[0]]
    while stack:
        link = stack.pop()
        reached.add(link)
        stack.extend(j.child for j in children[link])
    if len(roots) > 1 or len(reached) < len(robot.links):
        other = next(name for name in robot.links if name not in reached)
        if other in parent_of:
            joint = parent_of[other]
            raise ModelError(f"{path}:{joint.line}: joint {joint.name!r} is on a loop of joints not "
                             f"reached from the root link {roots[0]!r}")
        raise ModelError(f"{path}:{robot.link_lines[other]}: link {other!r} is not connected to the "
                         f"root link {roots[0]!r} (two roots)")
    for link in children:
        children[link].sort(key=lambda j: j.name)
    return children, roots[0]


def _combined(parts):
    """(mass, com (3,), central inertia (3, 3)) of several (mass, com, central inertia); none:
    no mass."""
    if not parts:
        return 0.0, np.zeros(3), np.zeros((3, 3))
    if len(parts) == 1:
        return parts[0]
    mass = sum(m for m, _, _ in parts)
    if mass == 0:
        return 0.0, np.zeros(3), sum((I for _, _, I in parts), np.zeros((3, 3)))
    com = sum(m * c for m, c, _ in parts) / mass
    inertia = np.zeros((3, 3))
    for m, c, I in parts:
        d = c - com
        inertia += I + m * (float(d @ d) * np.eye(3) - np.outer(d, d))
    return mass, com, inertia


def _table_number(x):
    """A float of the table: -0.0 written as 0.0, integers kept as floats."""
    return float(x) + 0.0


def urdf_tree(path, mimic=True, floating_base=False):
    """The joint table (model/joint_tree.py) of the URDF at ``path``: one row per moving joint
    in Pinocchio's order (module docstring). mimic=False: a mimic joint gets its own coordinate
    (as Pinocchio's parser without mimic=True does). floating_base=True: a first row "base" of
    type floating moves the root link (with the links fixed to it) freely."""
    robot = path if isinstance(path, Robot) else read_urdf(path)
    where = robot.path
    children, root = _children(robot)
    rows, parts, used = [], [], set()
    index_of_joint = {}

    def walk(link, body, R, p):
        """Add the joints below ``link``, whose frame is (R, p) in the frame of row ``body``
        (-1: the base)."""
        for joint in children[link]:
            Rj, pj = rpy_matrix(joint.rpy), joint.xyz
            R_c, p_c = R @ Rj, p + R @ pj
            inertial = robot.links[joint.child]
            if joint.kind == "fixed":
                if body >= 0 and inertial is not None:
                    parts[body].append((inertial.mass, p_c + R_c @ inertial.com, R_c @ inertial.inertia @ R_c.T))
                walk(joint.child, body, R_c, p_c)
                continue
            identity = np.array_equal(R, np.eye(3))
            rpy = joint.rpy if identity else matrix_rpy(R_c)
            row = {"name": make_identifier(joint.name, used), "link": joint.child, "parent": body,
                   "type": "prismatic" if joint.kind == "prismatic" else "revolute",
                   "axis": tuple(_table_number(a) for a in joint.axis),
                   "origin": tuple(_table_number(a) for a in snapped(p_c, max(1.0, float(np.abs(p_c).max())))),
                   "rpy": tuple(_table_number(a) for a in rpy)}
            if joint.mimic is not None and mimic:
                row["mimic"] = joint.mimic
            elif joint.limits is not None:
                row["limits"] = joint.limits
            index_of_joint[joint.name] = len(rows)
            rows.append(row)
            parts.append([] if inertial is None else [(inertial.mass, inertial.com, inertial.inertia)])
            walk(joint.child, len(rows) - 1, np.eye(3), np.zeros(3))

    if floating_base:
        rows.append({"name": make_identifier("base", used), "link": root, "parent": -1, "type": "floating"})
        inertial = robot.links[root]
        parts.append([] if inertial is None else [(inertial.mass, inertial.com, inertial.inertia)])
    walk(root, 0 if floating_base else -1, np.eye(3), np.zeros(3))
    _resolve_mimics(where, rows, index_of_joint, robot)
    _check_masses(where, rows, parts, robot)
    for row, body in zip(rows, parts):
        mass, com, inertia = _combined(body)
        scale = max(float(np.abs(inertia).max()), 1e-300)
        I = snapped(inertia, scale)
        row["mass"] = _table_number(mass)
        row["com"] = tuple(_table_number(c) for c in snapped(com, max(1.0, float(np.abs(com).max())) if mass else 1.0))
        row["inertia"] = tuple(_table_number(x) for x in (I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[1, 2], I[2, 0]))
        if "rpy" in row and not any(row["rpy"]):
            del row["rpy"]
        order = ["name", "link", "parent", "type", "axis", "origin", "rpy", "mimic", "limits", "mass", "com",
                 "inertia"]
        ordered = {k: row[k] for k in order if k in row}
        row.clear()
        row.update(ordered)
    return rows


def _resolve_mimics(where, rows, index_of_joint, robot):
    """Each row's "mimic" (URDF joint name, multiplier, offset, line) -> {"joint": the row name of
    a joint with its own coordinate, "multiplier", "offset"} (a mimic of a mimic composed)."""
    kinds = {j.name: j.kind for j in robot.joints}
    urdf_name = {j.child: j.name for j in robot.joints}
    resolved = {}

    def resolve(k, seen):
        row = rows[k]
        if "mimic" not in row:
            return row["name"], 1.0, 0.0
        if k not in resolved:
            other, multiplier, offset, line = row["mimic"]
            name = urdf_name[row["link"]]
            if other not in index_of_joint:
                why = "no joint of that name" if other not in kinds else f"it is a {kinds[other]} joint"
                raise ModelError(f"{where}:{line}: joint {name!r}: <mimic joint=\"{other}\">: {why}")
            j = index_of_joint[other]
            if j in seen:
                raise ModelError(f"{where}:{line}: joint {name!r}: <mimic> joints mimic each other in a loop")
            base, m2, o2 = resolve(j, seen | {j})
            resolved[k] = (base, multiplier * m2, multiplier * o2 + offset)
        return resolved[k]

    for k in range(len(rows)):
        resolve(k, {k})
    for k, (base, multiplier, offset) in resolved.items():
        rows[k]["mimic"] = {"joint": base, "multiplier": float(multiplier), "offset": float(offset)}


def _check_masses(where, rows, parts, robot):
    """ModelError for a coordinate that moves nothing with mass: neither below its own joint
    nor below the joints that mimic it (a mimic joint over massless links is no trouble: it
    has no column of its own)."""
    below = [sum(m for m, _, _ in body) for body in parts]
    for k in range(len(rows) - 1, -1, -1):
        if rows[k]["parent"] >= 0:
            below[rows[k]["parent"]] += below[k]
    moved = {row["name"]: below[k] for k, row in enumerate(rows) if "mimic" not in row}
    for k, row in enumerate(rows):
        if "mimic" in row:
            moved[row["mimic"]["joint"]] += below[k]
    joint_of = {j.child: j for j in robot.joints}
    for row in rows:
        if "mimic" not in row and moved[row["name"]] <= 0:
            if row["type"] == "floating":
                raise ModelError(f"{where}: nothing in the robot has mass (no <inertial>)")
            joint = joint_of[row["link"]]
            raise ModelError(f"{where}:{joint.line}: joint {joint.name!r} moves link "
                             f"{row['link']!r} and nothing with mass (a missing <inertial>?): "
                             "its column of the mass matrix would be zero")


# ------------------------------------------------------------------- Model and model file


def from_urdf(path, floating_base=False, g=9.81, mimic=True, limits=False, restitution=0.0, name=None,
              description=None):
    """The Model of the robot in the URDF file at ``path``, fixed to the ground: one coordinate
    ``q_<joint>`` per revolute, continuous or prismatic joint, in Pinocchio's order; fixed joints
    merged into their parent link; a mimic joint moved by the joint it mimics (mimic=False: a
    coordinate of its own, as Pinocchio's parser gives by default); T = lg.kinetic_energy of
    sympy.physics.mechanics RigidBodies, V = gravity -g along the base's z (the parameter g,
    default ``g``). limits=True: each <limit lower upper> of a joint with its own coordinate is
    two contacts (lg.Contact q - lower >= 0 and upper - q >= 0, Newton's ``restitution``), for
    the contact methods. Meshes and damping are not read. name: the model's name (default:
    the robot's, made an identifier). floating_base=True: the root link moves freely, six
    coordinates first (q_base_x, _y, _z: its origin in the base frame; q_base_rx, _ry, _rz:
    its angles about its own x, then y, then z), one chart of the rotations, singular at
    q_base_ry = +-pi/2 (forward_dynamics returns SINGULAR_MASS there). ModelError, one
    line naming the file, line and element, for a URDF that is malformed or not a tree of
    supported joints; ``lagrange-gen urdf`` writes the same model as an editable model file
    (docs/guides/from-urdf.md)."""
    robot = read_urdf(path)
    tree = urdf_tree(robot, mimic=mimic, floating_base=floating_base)
    if not tree:
        raise ModelError(f"{path}: the robot has no moving joint")
    return model_from_tree(name or make_identifier(robot.name, set()), tree, g=g, limits=limits,
                           restitution=restitution, description=description or _description(robot, path, tree))


def _row_text(row):
    def value(x):
        if isinstance(x, dict):
            return "{" + ", ".join(f"{k!r}: {value(v)}" for k, v in x.items()) + "}"
        if isinstance(x, tuple):
            return "(" + ", ".join(value(v) for v in x) + ("," if len(x) == 1 else "") + ")"
        return repr(x)
    head = ", ".join(f"{k!r}: {value(row[k])}" for k in ("name", "link", "parent", "type", "axis", "origin",
                                                           "rpy", "mimic", "limits") if k in row)
    body = ", ".join(f"{k!r}: {value(row[k])}" for k in ("mass", "com", "inertia"))
    return f"    {{{head},\n     {body}}},"


def _description(robot, path, tree):
    base = "floating base (one chart: singular at q_base_ry = +-pi/2)" if tree[0]["type"] == "floating" \
        else "fixed base"
    return f"{robot.name} from {Path(str(path)).name}: {n_dof(tree)} coordinates, {base}, gravity -g z"


def model_file_text(path, mimic=True, g=9.81, limits=False, floating_base=False):
    """The text of a model file that builds the URDF's robot from its joint table: edit TREE (or
    replace model_from_tree by your own mechanics code) and run lagrange-gen on it."""
    robot = read_urdf(path)
    tree = urdf_tree(robot, mimic=mimic, floating_base=floating_base)
    if not tree:
        raise ModelError(f"{path}: the robot has no moving joint")
    name = make_identifier(robot.name, set())
    base = ("\nThe first row, floating, moves the root link freely: q_base_x, _y, _z its origin in the base\n"
            "frame, q_base_rx, _ry, _rz its angles about its own x, then y, then z (one chart of the\n"
            "rotations: singular at q_base_ry = +-pi/2).\n" if floating_base else "")
    n = n_dof(tree)
    rows = "\n".join(_row_text(row) for row in tree)
    return f'''"""{robot.name}: {n} coordinates, {"floating" if floating_base else "fixed"} base (written by `lagrange-gen urdf {Path(str(path)).name}`).

The joint table of the URDF, one row per moving joint in Pinocchio's order (depth first from the
root link): parent (row index, -1: the base), type, origin (m) and
rpy (rad) of the joint frame in the parent's frame, axis in the joint frame, mimic (q = multiplier
* q_joint + offset: no coordinate of its own), limits (lower, upper: contacts with limits=True);
the child link's mass (kg), mass centre (m) in the joint frame and central inertia (ixx, iyy,
izz, ixy, iyz, izx) (kg m^2) in that frame, with the links of fixed joints merged in. Meshes
and damping are not read.
lagrange_gen.model.joint_tree.tree_bodies builds sympy.physics.mechanics frames and RigidBodies
from it; T = lg.kinetic_energy of the bodies, V = gravity -g along the base's z.
{base}"""
from lagrange_gen.model.joint_tree import model_from_tree

TREE = [
{rows}
]

model = model_from_tree({name!r}, TREE, g={float(g)!r},{" limits=True, restitution=0.0," if limits else ""}
                        description={_description(robot, path, tree)!r})
'''
