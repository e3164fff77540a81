"""Robots from example-robot-data's URDFs (the ``peers`` extra: pin, example-robot-data) against
Pinocchio's own URDF parser (fixed base, mimic joints as Pinocchio's mimic=True).

Each URDF goes through `lagrange-gen urdf` (a model file) and the generator; at random states the
module's mass matrix (dynamics), inverse dynamics (RNEA), forward dynamics with torques (ABA) and
without must equal pin.crba, pin.rnea and pin.aba to 1e-10 (relative to max(1, |value|)), the
coordinates must be Pinocchio's joints in Pinocchio's order, and a 7-DoF arm without mimic joints
must take its forward dynamics from the articulated-body algorithm. A few robots run by default;
``pytest --all-robots`` runs every URDF of the package (docs/guides/from-urdf.md lists them).
URDFs that have no moving joint or no robot in them are refused in one line.
"""

import importlib.metadata
from pathlib import Path

import numpy as np
import pytest

from lagrange_gen.cli.main import main
from lagrange_gen.codegen.generated_files import generate_model
from lagrange_gen.errors import ModelError
from lagrange_gen.model.urdf import model_file_text, urdf_tree
from lagrange_gen.run.loader import import_generated

pin = pytest.importorskip("pinocchio")

from lagrange_gen.bench.robots_peers import pinocchio_urdf  # noqa: E402  (needs pinocchio)


def _robots_dir():
    try:
        folder = importlib.metadata.distribution("example-robot-data").locate_file(
            "cmeel.prefix/share/example-robot-data/robots")
    except importlib.metadata.PackageNotFoundError:
        return None
    return Path(folder) if Path(folder).is_dir() else None


ROBOTS = _robots_dir()
if ROBOTS is None:
    pytest.skip("example-robot-data is not installed", allow_module_level=True)

#: run by default: a 6-DoF arm, mimic fingers, continuous joints, the 7-DoF arm, a branching tree
FEW = ["ur_description/urdf/ur5_robot.urdf", "panda_description/urdf/panda.urdf",
       "kinova_description/robots/kinova.urdf", "xarm_description/urdf/xarm7.urdf",
       "solo_description/robots/solo12.urdf"]
#: refused here, the reason in the message: no moving joint (Pinocchio: nq = 0), no robot
#: (Pinocchio fails too), a coordinate moving only massless links (Pinocchio loads them with a
#: singular mass matrix), a mimic of a joint that does not exist (Pinocchio's mimic=True fails)
REFUSED = {"hector_description/robots/quadrotor_base.urdf": "no moving joint",
           "iris_description/robots/iris_simple.urdf": "no moving joint",
           "ur_description/urdf/ur3.urdf": "has no <link>",
           "romeo_description/urdf/romeo.urdf": "joint 'LHand' moves link 'LFinger11Link' and nothing with mass",
           "romeo_description/urdf/romeo_laas_small.urdf": "joint 'l_gripper_joint' moves link 'l_gripper' and nothing",
           "alex_description/urdf/alex_psyonic_hands.urdf": "<mimic joint=\"index_q1\">: no joint of that name"}
#: compared with mimic joints as coordinates of their own on both sides (--no-mimic, Pinocchio's
#: mimic=False): Pinocchio's mimic=True wants a mimicked joint before its mimic in its order
OWN_COORDINATES = {"talos_data/robots/talos_full_v2.urdf", "talos_data/robots/talos_full_v2_box.urdf",
                   "alex_description/urdf/alex_psyonic_hands.urdf"}
ALL = sorted(str(p.relative_to(ROBOTS)) for p in ROBOTS.rglob("*.urdf"))
TOL = 1e-10
STATES = 3


def pytest_generate_tests(metafunc):
    if "robot" in metafunc.fixturenames:
        every = metafunc.config.getoption("--all-robots", default=False)
        cases = [r for r in (ALL if every else FEW) if r not in REFUSED or r in OWN_COORDINATES]
        metafunc.parametrize("robot", cases, ids=[Path(r).stem for r in cases], indirect=True)


@pytest.fixture
def robot(request, tmp_path):
    """(path, generated module, Pinocchio peer) of one URDF."""
    path, mimic = ROBOTS / request.param, request.param not in OWN_COORDINATES
    src = tmp_path / f"{Path(request.param).stem.replace('-', '_')}.py"
    assert main(["urdf", str(path), "-o", str(src)] + ([] if mimic else ["--no-mimic"])) == 0
    mod = import_generated(generate_model(src, tmp_path / "gen", methods=["rk4"]).path)
    return path, mod, pinocchio_urdf(path, mod.COORDS, mimic=mimic)


def _err(ours, theirs):
    theirs = np.asarray(theirs)
    return float(np.abs(np.asarray(ours) - theirs).max() / max(1.0, np.abs(theirs).max()))


def test_equals_pinocchio(robot):
    path, mod, peer = robot
    n, p = mod.N_COORDS, mod.DEFAULT_PARAMS
    assert list(mod.COORDS) == peer.names, "Pinocchio's joint order"
    rng = np.random.default_rng(44)
    for _ in range(STATES):
        q, v, a, tau = rng.uniform(-2, 2, n), rng.normal(size=n), rng.normal(size=n), rng.normal(size=n)
        H, rhs = np.zeros((n, n)), np.zeros(n)
        mod.dynamics.py_func(q, v, 0.0, p, H, rhs)
        assert _err(H, peer.crba(q)) < TOL
        out = np.zeros(n)
        mod.inverse_dynamics.py_func(q, v, a, 0.0, p, out)
        assert _err(out, peer.rnea(q, v, a)) < TOL
        if hasattr(mod, "forward_dynamics_torques"):
            assert mod.forward_dynamics_torques.py_func(q, v, tau, 0.0, p, np.zeros((n, n)), out) == 0
        else:                                       # a constant H: no recursive kernels
            out = np.linalg.solve(H, rhs + tau)
        assert _err(out, peer.aba(q, v, tau)) < TOL
        assert mod.forward_dynamics.py_func(q, v, 0.0, p, np.zeros((n, n)), out) == 0
        assert _err(out, peer.aba(q, v, np.zeros(n))) < TOL


def test_a_7_dof_arm_takes_the_articulated_body_algorithm(tmp_path):
    src = tmp_path / "xarm7.py"
    assert main(["urdf", str(ROBOTS / "xarm_description/urdf/xarm7.urdf"), "-o", str(src)]) == 0
    mod = import_generated(generate_model(src, tmp_path / "gen", methods=["rk4"]).path)
    assert mod.N_COORDS == 7 and "articulated-body" in mod.forward_dynamics.__doc__


@pytest.mark.parametrize("name", sorted(REFUSED))
def test_urdfs_without_a_moving_joint_are_refused_in_one_line(name):
    with pytest.raises(ModelError, match=REFUSED[name]) as info:
        model_file_text(ROBOTS / name)
    assert "\n" not in str(info.value)


def test_child_joints_come_in_the_order_of_their_names_as_in_pinocchio(tmp_path):
    """tests/model/data/arm_mimic.urdf with the branch joint renamed so that it sorts before its
    sibling listed first in the file: Pinocchio (through urdfdom's map of joints) puts it first,
    and so does urdf_tree (mimic off: Pinocchio wants a mimicked joint before its mimic)."""
    text = (Path(__file__).parents[1] / "model" / "data" / "arm_mimic.urdf").read_text()
    path = tmp_path / "renamed.urdf"
    path.write_text(text.replace('name="finger"', 'name="aaa_finger"'))
    names = [name.replace("-", "_") for name in list(pin.buildModelFromUrdf(str(path)).names)[1:]]
    assert names[1] == "aaa_finger"
    assert [row["name"] for row in urdf_tree(path, mimic=False)] == names


@pytest.mark.parametrize("name", ["panda_description/urdf/panda.urdf", "talos_data/robots/talos_full_v2.urdf"],
                         ids=["panda", "talos_full_v2"])
def test_mimic_joints_equal_pinocchio_without_mimic_projected(request, tmp_path, name):
    """Our mimic joints (no coordinate of their own) against Pinocchio's model with every joint
    a coordinate (mimic=False), projected on q_full = G q + c: M = G^T M_full G, the inverse
    dynamics G^T rnea_full(G q + c, G v, G a). Talos's grippers (12 mimic joints) Pinocchio's
    mimic=True does not load; it runs with --all-robots."""
    if name != FEW[1] and not request.config.getoption("--all-robots"):
        pytest.skip("--all-robots")
    path = ROBOTS / name
    src = tmp_path / "robot.py"
    assert main(["urdf", str(path), "-o", str(src)]) == 0
    mod = import_generated(generate_model(src, tmp_path / "gen", methods=["rk4"]).path)
    rows = urdf_tree(path)
    peer = pinocchio_urdf(path, ["q_" + row["name"] for row in rows], mimic=False)
    n, p, own = mod.N_COORDS, mod.DEFAULT_PARAMS, list(mod.COORDS)
    G, c = np.zeros((len(rows), n)), np.zeros(len(rows))
    for k, row in enumerate(rows):
        mimic = row.get("mimic", {"joint": row["name"], "multiplier": 1.0, "offset": 0.0})
        G[k, own.index("q_" + mimic["joint"])], c[k] = mimic["multiplier"], mimic["offset"]
    assert n < len(rows)
    rng = np.random.default_rng(45)
    for _ in range(STATES):
        q, v, a = rng.uniform(-2, 2, n), rng.normal(size=n), rng.normal(size=n)
        H, rhs, out = np.zeros((n, n)), np.zeros(n), np.zeros(n)
        mod.dynamics.py_func(q, v, 0.0, p, H, rhs)
        M = G.T @ peer.crba(G @ q + c) @ G
        assert _err(H, M) < TOL
        mod.inverse_dynamics.py_func(q, v, a, 0.0, p, out)
        assert _err(out, G.T @ peer.rnea(G @ q + c, G @ v, G @ a)) < TOL
        assert mod.forward_dynamics.py_func(q, v, 0.0, p, np.zeros((n, n)), out) == 0
        assert _err(out, np.linalg.solve(M, -G.T @ peer.rnea(G @ q + c, G @ v, np.zeros(len(rows))))) < TOL


@pytest.mark.parametrize("name", ["solo_description/robots/solo12.urdf", "ur_description/urdf/ur5_robot.urdf"],
                         ids=["solo12", "ur5"])
def test_floating_base_equals_pinocchio_in_the_same_chart(tmp_path, name):
    """--floating-base: the root link's x, y, z and angles about its own x, y, z against
    Pinocchio with a composite root joint PX PY PZ RX RY RZ (the same chart), by ABA."""
    path = ROBOTS / name
    src = tmp_path / "robot.py"
    assert main(["urdf", str(path), "-o", str(src), "--floating-base"]) == 0
    mod = import_generated(generate_model(src, tmp_path / "gen", methods=["rk4"]).path)
    assert list(mod.COORDS[:6]) == [f"q_base_{c}" for c in ("x", "y", "z", "rx", "ry", "rz")]
    assert "articulated-body" in mod.forward_dynamics.__doc__
    peer = pinocchio_urdf(path, mod.COORDS, floating=True)
    n, p = mod.N_COORDS, mod.DEFAULT_PARAMS
    rng = np.random.default_rng(46)
    for _ in range(STATES):
        q, v, a, tau = (rng.uniform(-1.2, 1.2, n), rng.normal(size=n), rng.normal(size=n),
                        rng.normal(size=n))
        H, rhs, out = np.zeros((n, n)), np.zeros(n), np.zeros(n)
        mod.dynamics.py_func(q, v, 0.0, p, H, rhs)
        assert _err(H, peer.crba(q)) < TOL
        mod.inverse_dynamics.py_func(q, v, a, 0.0, p, out)
        assert _err(out, peer.rnea(q, v, a)) < TOL
        assert mod.forward_dynamics_torques.py_func(q, v, tau, 0.0, p, H, out) == 0
        assert _err(out, peer.aba(q, v, tau)) < TOL
