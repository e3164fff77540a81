"""Robots from URDF (model/urdf.py, `lagrange-gen urdf`): a small arm (data/arm_mimic.urdf: joint
origins with rpy, rotated inertials, a fixed joint merged into its parent, a mimic joint, a
massless moving link carrying a massive one, a link without inertial, a package:// mesh) against
an independent numpy computation written here from the URDF's transforms (parsed with
xml.etree, not our parser): the mass matrix from the links' geometric Jacobians
(M = sum m Jv^T Jv + Jw^T I Jw), gravity by central differences of V = sum m g z, the bias
forces from the Christoffel symbols of differenced M. Bad input: one line with the line number,
a ModelError, exit code 2 from the command and no file written."""

import math
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from lagrange_gen.cli.main import main
from lagrange_gen.codegen.generated_files import generate_model
from lagrange_gen.errors import ModelError
from lagrange_gen.model.joint_tree import rpy_matrix
from lagrange_gen.model.urdf import from_urdf, matrix_rpy, model_file_text, urdf_tree
from lagrange_gen.run.loader import import_generated

ARM = Path(__file__).parent / "data" / "arm_mimic.urdf"
G = 9.81
#: Pinocchio's order: depth first from the root, a link's child joints by name (elbow < finger)
ORDER = ["shoulder", "elbow", "slide", "wrist_roll", "wrist_pitch", "finger"]


# ------------------------------------------------------------- the independent reference


def _floats(text, default):
    return np.array([float(x) for x in text.split()]) if text else np.array(default, dtype=float)


def _rot(rpy):
    r, p, y = rpy
    Rx = np.array([[1, 0, 0], [0, math.cos(r), -math.sin(r)], [0, math.sin(r), math.cos(r)]])
    Ry = np.array([[math.cos(p), 0, math.sin(p)], [0, 1, 0], [-math.sin(p), 0, math.cos(p)]])
    Rz = np.array([[math.cos(y), -math.sin(y), 0], [math.sin(y), math.cos(y), 0], [0, 0, 1]])
    return Rz @ Ry @ Rx


def _axis_angle(axis, angle):
    k = axis / np.linalg.norm(axis)
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + math.sin(angle) * K + (1 - math.cos(angle)) * K @ K


class Reference:
    """Forward kinematics of the URDF over the coordinates ``coords`` (joint names; a mimic
    joint not among them follows its joint). floating: the root link carried by six joints
    base_x, _y, _z (slides along the world's axes) and base_rx, _ry, _rz (turns about the
    moved frame's x, then y, then z)."""

    def __init__(self, path, coords, floating=False):
        root = ET.parse(path).getroot()
        self.coords = coords
        self.inertials = {}
        for link in root.findall("link"):
            inertial = link.find("inertial")
            if inertial is None:
                continue
            origin = inertial.find("origin")
            xyz = _floats(origin.get("xyz") if origin is not None else None, (0, 0, 0))
            rpy = _floats(origin.get("rpy") if origin is not None else None, (0, 0, 0))
            i = {k: float(inertial.find("inertia").get(k)) for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")}
            I = np.array([[i["ixx"], i["ixy"], i["ixz"]], [i["ixy"], i["iyy"], i["iyz"]], [i["ixz"], i["iyz"], i["izz"]]])
            self.inertials[link.get("name")] = (float(inertial.find("mass").get("value")), xyz, _rot(rpy), I)
        self.joints = []
        for joint in root.findall("joint"):
            origin, axis, mimic = joint.find("origin"), joint.find("axis"), joint.find("mimic")
            self.joints.append(dict(
                name=joint.get("name"), type=joint.get("type"), parent=joint.find("parent").get("link"),
                child=joint.find("child").get("link"),
                xyz=_floats(origin.get("xyz") if origin is not None else None, (0, 0, 0)),
                rpy=_floats(origin.get("rpy") if origin is not None else None, (0, 0, 0)),
                axis=_floats(axis.get("xyz") if axis is not None else None, (1, 0, 0)),
                mimic=None if mimic is None else (mimic.get("joint"), float(mimic.get("multiplier", 1)),
                                                  float(mimic.get("offset", 0)))))
        children = {j["child"] for j in self.joints}
        self.root = next(link.get("name") for link in root.findall("link") if link.get("name") not in children)
        if floating:
            chain = ["world", "bx", "by", "bz", "brx", "bry", self.root]
            for k, (kind, axis) in enumerate([("prismatic", (1, 0, 0)), ("prismatic", (0, 1, 0)),
                                              ("prismatic", (0, 0, 1)), ("revolute", (1, 0, 0)),
                                              ("revolute", (0, 1, 0)), ("revolute", (0, 0, 1))]):
                self.joints.insert(k, dict(name=f"base_{['x', 'y', 'z', 'rx', 'ry', 'rz'][k]}", type=kind,
                                           parent=chain[k], child=chain[k + 1], xyz=np.zeros(3), rpy=np.zeros(3),
                                           axis=np.array(axis, dtype=float), mimic=None))
            self.root = "world"

    def _value(self, joint, q):
        """(joint value, {coordinate index: d value / d q}) of a joint."""
        name = joint["name"]
        if name in self.coords:
            k = self.coords.index(name)
            return q[k], {k: 1.0}
        other, m, c = joint["mimic"]
        k = self.coords.index(other)
        return m * q[k] + c, {k: m}

    def links(self, q):
        """[(mass, com (3,), inertia in the world (3, 3), Jv (3, n), Jw (3, n))] of the links
        with an inertial, at q."""
        n = len(self.coords)
        pose = {self.root: (np.eye(3), np.zeros(3), np.zeros((3, n)), np.zeros((3, n)), [])}
        pending = list(self.joints)
        while pending:
            joint = next(j for j in pending if j["parent"] in pose)
            pending.remove(joint)
            R, p, _, _, movers = pose[joint["parent"]]
            Rj, pj = R @ _rot(joint["rpy"]), p + R @ joint["xyz"]
            movers = list(movers)
            if joint["type"] != "fixed":
                value, weights = self._value(joint, q)
                axis_world = Rj @ (joint["axis"] / np.linalg.norm(joint["axis"]))
                movers.append((joint["type"], axis_world, pj.copy(), weights))
                if joint["type"] == "prismatic":
                    pj = pj + axis_world * value
                else:
                    Rj = Rj @ _axis_angle(joint["axis"], value)
            pose[joint["child"]] = (Rj, pj, None, None, movers)
        out = []
        for link, (mass, xyz, R_in, I) in self.inertials.items():
            if link == self.root:
                continue
            R, p, _, _, movers = pose[link]
            com = p + R @ xyz
            Jv, Jw = np.zeros((3, n)), np.zeros((3, n))
            for kind, axis, point, weights in movers:
                for k, w in weights.items():
                    if kind == "prismatic":
                        Jv[:, k] += w * axis
                    else:
                        Jv[:, k] += w * np.cross(axis, com - point)
                        Jw[:, k] += w * axis
            R_I = R @ R_in
            out.append((mass, com, R_I @ I @ R_I.T, Jv, Jw))
        return out

    def mass_matrix(self, q):
        return sum(m * Jv.T @ Jv + Jw.T @ I @ Jw for m, _, I, Jv, Jw in self.links(q))

    def potential(self, q):
        return sum(m * G * c[2] for m, c, _, _, _ in self.links(q))

    def gravity(self, q, h=1e-6):
        return np.array([(self.potential(q + h * e) - self.potential(q - h * e)) / (2 * h)
                         for e in np.eye(len(q))])

    def coriolis(self, q, v, h=1e-6):
        """C(q, v) v = dM/dt v - 1/2 d(v^T M v)/dq, dM/dq_k by central differences."""
        dM = [(self.mass_matrix(q + h * e) - self.mass_matrix(q - h * e)) / (2 * h) for e in np.eye(len(q))]
        Mdot = sum(d * vk for d, vk in zip(dM, v))
        return Mdot @ v - 0.5 * np.array([v @ d @ v for d in dM])


# ------------------------------------------------------------------------ the modules


FLOATING = ["base_x", "base_y", "base_z", "base_rx", "base_ry", "base_rz"]


@pytest.fixture(scope="module")
def modules(tmp_path_factory):
    """{case: (generated module, Reference)}: the model file written by `lagrange-gen urdf`
    (True: as it is; False: --no-mimic; "floating": --floating-base), generated once each."""
    out, built = tmp_path_factory.mktemp("urdf"), {}
    for case, options in ((True, []), (False, ["--no-mimic"]), ("floating", ["--floating-base"])):
        src = out / f"arm_{case}.py"
        assert main(["urdf", str(ARM), "-o", str(src)] + options) == 0
        mod = import_generated(generate_model(src, out / f"gen_{case}", methods=["rk4"]).path)
        coords = (FLOATING if case == "floating" else []) + (ORDER if case is False else ORDER[:-1])
        built[case] = (mod, Reference(ARM, [c.replace("wrist_roll", "wrist-roll") for c in coords],
                                      floating=case == "floating"))
    return built


def _states(n, count=3, seed=7):
    rng = np.random.default_rng(seed)
    return [(rng.uniform(-2, 2, n), rng.normal(size=n)) for _ in range(count)]


def _rel(a, b):
    return float(np.abs(np.asarray(a) - np.asarray(b)).max() / max(np.abs(b).max(), 1e-12))


CASES = [True, False, "floating"]
IDS = ["mimic", "no-mimic", "floating"]


@pytest.mark.parametrize("mimic", CASES, ids=IDS)
def test_coordinates_are_the_joints_in_pinocchios_order(modules, mimic):
    mod, _ = modules[mimic]
    expected = (FLOATING if mimic == "floating" else []) + (ORDER if mimic is False else ORDER[:-1])
    assert list(mod.COORDS) == [f"q_{name}" for name in expected]


@pytest.mark.parametrize("mimic", CASES, ids=IDS)
def test_mass_matrix_equals_the_links_jacobians(modules, mimic):
    mod, ref = modules[mimic]
    n = mod.N_COORDS
    for q, v in _states(n):
        H, rhs = np.zeros((n, n)), np.zeros(n)
        mod.dynamics.py_func(q, v, 0.0, mod.DEFAULT_PARAMS, H, rhs)
        assert _rel(H, ref.mass_matrix(q)) < 1e-12


@pytest.mark.parametrize("mimic", CASES, ids=IDS)
def test_gravity_and_bias_forces_equal_differenced_energies(modules, mimic):
    mod, ref = modules[mimic]
    n, p = mod.N_COORDS, mod.DEFAULT_PARAMS
    for q, v in _states(n):
        g, bias, H, rhs = np.zeros(n), np.zeros(n), np.zeros((n, n)), np.zeros(n)
        mod.gravity_forces.py_func(q, 0.0, p, g)
        mod.bias_forces.py_func(q, v, 0.0, p, bias)
        mod.dynamics.py_func(q, v, 0.0, p, H, rhs)
        g_ref, c_ref = ref.gravity(q), ref.coriolis(q, v)
        assert _rel(g, g_ref) < 1e-8
        assert _rel(bias, g_ref + c_ref) < 1e-7
        assert _rel(rhs, -(g_ref + c_ref)) < 1e-7


def test_a_tree_without_mimic_takes_the_articulated_body_algorithm(modules):
    """rpy rows keep the recursive path; a mimic joint (one coordinate moving two joints) keeps
    H + Cholesky."""
    assert "articulated-body" in modules[False][0].forward_dynamics.__doc__
    assert "floating base" in modules["floating"][0].__doc__
    assert "articulated-body" not in modules[True][0].forward_dynamics.__doc__


def test_the_table_merges_the_fixed_joint_and_keeps_the_massless_link():
    rows = {row["name"]: row for row in urdf_tree(ARM)}
    assert rows["elbow"]["mass"] == pytest.approx(1.5 + 0.5)          # tool merged into link2
    assert rows["wrist_roll"]["mass"] == 0.0 and rows["wrist_roll"]["link"] == "link5"
    assert rows["finger"]["mimic"] == {"joint": "elbow", "multiplier": -0.5, "offset": 0.2}
    assert "rpy" not in rows["shoulder"] or rows["shoulder"]["rpy"] == (0.0, 0.0, 0.4)


def test_from_urdf_builds_the_model():
    model = from_urdf(ARM, g=3.0)
    assert [str(q) for q in model.coords] == [f"q_{name}" for name in ORDER[:-1]]
    assert len(from_urdf(ARM, floating_base=True).coords) == 6 + len(ORDER) - 1


def test_joint_limits_become_contacts_on_request():
    """<limit lower upper> of the joints with a coordinate (not the continuous elbow, not the
    mimic finger): gaps q - lower and upper - q."""
    assert not from_urdf(ARM).contacts
    model = from_urdf(ARM, limits=True, restitution=0.5)
    expected = {"shoulder": (-2, 2), "slide": (0, 0.1), "wrist_roll": (-3, 3), "wrist_pitch": (-3, 3)}
    assert [c.name for c in model.contacts] == [f"{j}_{side}" for j in expected for side in ("lower", "upper")]
    at = dict(zip(model.coords, [0.5, 0.1, 0.02, -1.0, 2.5]))
    values = dict(zip(["shoulder", "elbow", "slide", "wrist_roll", "wrist_pitch"], at.values()))
    for contact in model.contacts:
        joint, side = contact.name.rsplit("_", 1)
        lower, upper = expected[joint]
        gap = values[joint] - lower if side == "lower" else upper - values[joint]
        assert float(contact.gap.xreplace(at)) == pytest.approx(gap, abs=1e-15)
        assert float(contact.restitution) == 0.5
    assert "limits=True" in model_file_text(ARM, limits=True)


def test_rpy_of_a_matrix_near_gimbal_lock():
    for pitch in (math.pi / 2, math.pi / 2 - 1e-9, -math.pi / 2 + 3e-8, 0.3):
        R = rpy_matrix((0.7, pitch, -1.1)) @ rpy_matrix((0.2, 0.1, 0.3))
        assert np.abs(rpy_matrix(matrix_rpy(R)) - R).max() < 1e-15


def test_the_model_file_is_readable_and_refuses_to_overwrite(tmp_path, capsys):
    text = model_file_text(ARM)
    assert "TREE = [" in text and "'mimic': {'joint': 'elbow'" in text and "package://" not in text
    out = tmp_path / "arm.py"
    assert main(["urdf", str(ARM), "-o", str(out)]) == 0
    assert main(["urdf", str(ARM), "-o", str(out)]) == 2
    assert "exists" in capsys.readouterr().err


# -------------------------------------------------------------------------- bad input


def _with(old, new):
    text = ARM.read_text()
    assert old in text
    return text.replace(old, new, 1)


def _line(text, fragment):
    return text[:text.index(fragment)].count("\n") + 1


BAD = {
    "malformed": (lambda: _with('<mass value="0.4"/>', '<mass value=0.4/>'), "malformed XML", '<mass value=0.4/>'),
    "planar": (lambda: _with('name="slide" type="prismatic"', 'name="slide" type="planar"'),
               "joint 'slide': type 'planar' is not supported", 'name="slide"'),
    "loop": (lambda: _with('</robot>', '<joint name="back" type="fixed"><parent link="link4"/>'
                                       '<child link="link2"/></joint>\n</robot>'),
             "link 'link2' already has the parent joint 'elbow'", 'name="back"'),
    "cycle": (lambda: _with('</robot>', '<joint name="around" type="fixed"><parent link="link4"/>'
                                        '<child link="base_link"/></joint>\n</robot>'),
              "joint 'shoulder' is on a loop of joints", 'name="shoulder"'),
    "missing inertial": (lambda: _with('<mass value="0.3"/>', '<mass value="0.0"/>'),
                         "joint 'wrist-roll' moves link 'link5' and nothing with mass", 'name="wrist-roll"'),
    "unknown mimic": (lambda: _with('<mimic joint="elbow"', '<mimic joint="elbo"'),
                      "<mimic joint=\"elbo\">: no joint of that name", '<mimic joint="elbo"'),
    "mimic of a fixed joint": (lambda: _with('<mimic joint="elbow"', '<mimic joint="tool_mount"'),
                               "it is a fixed joint", '<mimic joint="tool_mount"'),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_input_is_one_line_with_its_line_number(tmp_path, capsys, case):
    make, message, fragment = BAD[case]
    text = make()
    path = tmp_path / "bad.urdf"
    path.write_text(text)
    with pytest.raises(ModelError) as info:
        urdf_tree(path)
    assert message in str(info.value) and "\n" not in str(info.value)
    assert str(info.value).startswith(f"{path}:{_line(text, fragment)}:")
    out = tmp_path / "bad.py"
    assert main(["urdf", str(path), "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and message in err and not out.exists()


def test_the_floating_base_chart_is_singular_only_at_pitch_90_degrees(modules):
    """One chart of the rotations: at q_base_ry = pi/2 the angle rates do not determine the
    angular velocity, H is singular and forward_dynamics says so (SINGULAR_MASS) instead of
    returning accelerations; a tenth of a radian away it solves."""
    mod, _ = modules["floating"]
    n = mod.N_COORDS
    q = np.random.default_rng(3).uniform(-1, 1, n)
    for pitch, solves in ((math.pi / 2, False), (math.pi / 2 - 0.1, True), (-math.pi / 2, False)):
        q[4] = pitch
        qdd = np.zeros(n)
        status = mod.forward_dynamics.py_func(q, np.zeros(n), 0.0, mod.DEFAULT_PARAMS, np.zeros((n, n)), qdd)
        assert (status == 0) == solves
