"""Random spatial trees (issue 28, item 4) built both ways from one joint table, against Pinocchio.

Each tree (lagrange_gen.analysis.random_trees.random_tree: random parents, unit axes, offsets,
masses, positive definite full inertia tensors; 3 to 6 bodies, revolute and prismatic joints)
is written to a model file that builds it with sympy.physics.mechanics (model_from_tree), and
given to Pinocchio (bench/robots_peers.pinocchio_model). At random states our generated module
must give Pinocchio's mass matrix (crba), accelerations (aba, also with joint torques: H qdd =
rhs + tau), inverse dynamics (rnea: tau = H a - rhs) and acceleration derivatives
(computeABADerivatives: H dqdd/dq = d rhs/dq - d(H w)/dq at w = qdd, H dqdd/dqd = d rhs/dqd),
to 1e-9 relative.

A second check needs no Pinocchio: on a 3-body tree, H and rhs equal those of Lagrange's
equations derived here with plain sympy on explicit rotation matrices (Rodrigues' formula), not
through lagrange_gen.derive or sympy.physics.mechanics.

The kernels are called as their Python functions (``py_func``): the numba compile of the larger
trees' Jacobian kernels would take minutes and is not what is tested; forward_dynamics of the
smallest tree runs compiled, once.
"""

import json

import numpy as np
import pytest
import sympy as sp

from lagrange_gen.analysis.random_trees import random_tree
from lagrange_gen.codegen import generate_model
from lagrange_gen.run.loader import import_generated

pin = pytest.importorskip("pinocchio")

from lagrange_gen.bench import robots_peers  # noqa: E402  (needs pinocchio)

RTOL = 1e-9
#: (bodies, seed): every size 3..6; the seeds draw prismatic joints and branching
CASES = [(3, 1), (4, 10), (5, 10), (6, 8)]
STATES = 3


def _rel(a, b):
    return float(np.abs(np.asarray(a) - np.asarray(b)).max() / max(np.abs(b).max(), 1e-12))


def _model_file(path, name, tree):
    path.write_text("from lagrange_gen.model.joint_tree import model_from_tree\n\n"
                    f"TREE = {json.dumps(tree, indent=1)}\n\n"
                    f"model = model_from_tree({name!r}, TREE, g=9.81)\n")
    return path


@pytest.fixture(scope="module")
def trees(tmp_path_factory):
    """{(n, seed): (tree, generated module)}, each generated once with the kernels implicit
    Euler needs (dynamics, rhs_jacobian, mass_matvec_dq, forward_dynamics)."""
    out, built = tmp_path_factory.mktemp("pin_trees"), {}
    for n, seed in CASES:
        tree = random_tree(np.random.default_rng(seed), n)
        name = f"random_tree_{n}_{seed}"
        src = _model_file(out / f"{name}.py", name, tree)
        result = generate_model(src, out / "gen", methods=["implicit_euler"])
        built[(n, seed)] = (tree, import_generated(result.path))
    return built


def _kernels(mod):
    return (mod.dynamics.py_func, mod.rhs_jacobian.py_func, mod.mass_matvec_dq.py_func)


def _states(n, seed):
    rng = np.random.default_rng(1000 + seed)
    for _ in range(STATES):
        yield rng.uniform(-2, 2, n), rng.normal(size=n), rng.normal(size=n), rng.normal(size=n)


def test_the_draws_cover_prismatic_joints_and_branching():
    kinds, branched = set(), False
    for n, seed in CASES:
        tree = random_tree(np.random.default_rng(seed), n)
        kinds |= {j["type"] for j in tree}
        parents = [j["parent"] for j in tree]
        branched |= len(set(parents)) < len(parents)
    assert kinds == {"revolute", "prismatic"} and branched


@pytest.mark.parametrize("case", CASES, ids=lambda c: f"{c[0]}bodies-seed{c[1]}")
def test_mass_matrix_accelerations_and_inverse_dynamics_equal_pinocchio(trees, case):
    tree, mod = trees[case]
    n, p = len(tree), mod.DEFAULT_PARAMS
    peer = robots_peers.pinocchio_model(tree, g=float(p[list(mod.PARAMS).index("g")]))
    dynamics = _kernels(mod)[0]
    for q, v, tau, a in _states(*case):
        H, rhs = np.zeros((n, n)), np.zeros(n)
        dynamics(q, v, 0.0, p, H, rhs)
        assert _rel(H, robots_peers.crba(peer, q)) < RTOL
        assert _rel(np.linalg.solve(H, rhs), robots_peers.aba(peer, q, v, np.zeros(n))) < RTOL
        assert _rel(np.linalg.solve(H, rhs + tau), robots_peers.aba(peer, q, v, tau)) < RTOL
        assert _rel(H @ a - rhs, robots_peers.rnea(peer, q, v, a)) < RTOL
        qdd = np.zeros(n)
        assert mod.forward_dynamics.py_func(q, v, 0.0, p, np.zeros((n, n)), qdd) == 0
        assert _rel(qdd, robots_peers.aba(peer, q, v, np.zeros(n))) < RTOL


@pytest.mark.parametrize("case", CASES, ids=lambda c: f"{c[0]}bodies-seed{c[1]}")
def test_acceleration_derivatives_equal_pinocchio(trees, case):
    tree, mod = trees[case]
    n, p = len(tree), mod.DEFAULT_PARAMS
    peer = robots_peers.pinocchio_model(tree)
    dynamics, rhs_jacobian, mass_matvec_dq = _kernels(mod)
    for q, v, tau, _ in _states(*case):
        H, rhs = np.zeros((n, n)), np.zeros(n)
        dynamics(q, v, 0.0, p, H, rhs)
        qdd = np.linalg.solve(H, rhs + tau)
        Jq, Jqd, D = np.zeros((n, n)), np.zeros((n, n)), np.zeros((n, n))
        rhs_jacobian(q, v, 0.0, p, Jq, Jqd)
        mass_matvec_dq(q, qdd, 0.0, p, D)
        dq, dv = robots_peers.aba_derivatives(peer, q, v, tau)
        assert _rel(np.linalg.solve(H, Jq - D), dq) < RTOL
        assert _rel(np.linalg.solve(H, Jqd), dv) < RTOL


def test_compiled_forward_dynamics_equals_pinocchio(trees):
    tree, mod = trees[CASES[0]]
    n = len(tree)
    peer = robots_peers.pinocchio_model(tree)
    q, v, _, _ = next(_states(*CASES[0]))
    qdd = np.zeros(n)
    assert mod.forward_dynamics(q, v, 0.0, mod.DEFAULT_PARAMS, np.zeros((n, n)), qdd) == 0
    assert _rel(qdd, robots_peers.aba(peer, q, v, np.zeros(n))) < RTOL


def test_pinocchio_peer_adds_joints_depth_first():
    """Two chains from the base given alternately: Pinocchio's crba is only right on a depth-
    first joint order (a wrong order gives a wrong mass matrix, silently); the peer reorders and
    its mass matrix equals the one rnea gives column by column."""
    tree = random_tree(np.random.default_rng(1), 4)
    assert [j["parent"] for j in tree] == [-1, -1, 0, 1]
    peer = robots_peers.pinocchio_model(tree)
    assert peer.order == [0, 2, 1, 3]
    q = np.random.default_rng(2).normal(size=4)
    g0 = robots_peers.rnea(peer, q, np.zeros(4), np.zeros(4))
    by_rnea = np.column_stack([robots_peers.rnea(peer, q, np.zeros(4), e) - g0 for e in np.eye(4)])
    assert _rel(robots_peers.crba(peer, q), by_rnea) < 1e-12


# ------------------------------------------------ independent plain-sympy Lagrange derivation


def _rodrigues(axis, angle):
    k = sp.Matrix(axis) / sp.sqrt(sum(sp.Float(a) ** 2 for a in axis))
    K = sp.Matrix([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return sp.eye(3) + sp.sin(angle) * K + (1 - sp.cos(angle)) * K * K


def lagrange_reference(tree, g=9.81):
    """(H(q), rhs(q, qd)) as numpy functions, from L = T - V with every body's rotation matrix
    R (world from body) and mass-centre position c written out: T = sum m |dc/dt|^2 / 2 +
    w^T I w / 2 with the body angular velocity skew(w) = R^T dR/dt, V = sum m g c_z;
    H = d2L/dqd2, rhs = dL/dq - d2L/dqd dq qd (so that H qdd = rhs)."""
    n = len(tree)
    q = sp.symbols(f"q0:{n}")
    qd = sp.symbols(f"qd0:{n}")
    R_of, p_of, T, V = {}, {}, sp.S.Zero, sp.S.Zero
    for i, joint in enumerate(tree):
        parent = joint["parent"]
        R_p = sp.eye(3) if parent < 0 else R_of[parent]
        p_p = sp.zeros(3, 1) if parent < 0 else p_of[parent]
        J = p_p + R_p * sp.Matrix(joint["origin"])
        if joint["type"] == "revolute":
            R, origin = R_p * _rodrigues(joint["axis"], q[i]), J
        else:
            unit = sp.Matrix(joint["axis"]) / sp.sqrt(sum(sp.Float(a) ** 2 for a in joint["axis"]))
            R, origin = R_p, J + R_p * unit * q[i]
        R_of[i], p_of[i] = R, origin
        c = origin + R * sp.Matrix(joint["com"])
        vel = c.jacobian(q) * sp.Matrix(qd)
        Rdot = sum((R.diff(q[j]) * qd[j] for j in range(n)), sp.zeros(3, 3))
        W = R.T * Rdot
        w = sp.Matrix([W[2, 1], W[0, 2], W[1, 0]])
        ixx, iyy, izz, ixy, iyz, izx = joint["inertia"]
        I = sp.Matrix([[ixx, ixy, izx], [ixy, iyy, iyz], [izx, iyz, izz]])
        m = joint["mass"]
        T += m * vel.dot(vel) / 2 + (w.T * I * w)[0] / 2
        V += m * g * c[2]
    L = T - V
    dL_dqd = sp.Matrix([L.diff(x) for x in qd])
    H = dL_dqd.jacobian(qd)
    rhs = sp.Matrix([L.diff(x) for x in q]) - dL_dqd.jacobian(q) * sp.Matrix(qd)
    fH = sp.lambdify([q], H, cse=True)
    frhs = sp.lambdify([q, qd], rhs, cse=True)
    return (lambda qv: np.array(fH(qv), dtype=float),
            lambda qv, vv: np.array(frhs(qv, vv), dtype=float).ravel())


def test_derivation_equals_plain_sympy_lagrange_on_a_3_body_tree(trees):
    tree, mod = trees[CASES[0]]
    assert len(tree) == 3
    H_ref, rhs_ref = lagrange_reference(tree)
    dynamics = _kernels(mod)[0]
    for q, v, _, _ in _states(*CASES[0]):
        H, rhs = np.zeros((3, 3)), np.zeros(3)
        dynamics(q, v, 0.0, mod.DEFAULT_PARAMS, H, rhs)
        assert _rel(H, H_ref(q)) < RTOL
        assert _rel(rhs, rhs_ref(q, v)) < RTOL


@pytest.mark.parametrize("case", CASES, ids=lambda c: f"{c[0]}bodies-seed{c[1]}")
def test_robot_kernels_equal_pinocchio(trees, case):
    """The module's own robot kernels, not compositions of ours: inverse_dynamics = rnea,
    gravity_forces = rnea(q, 0, 0), bias_forces = rnea(q, v, 0) (nonLinearEffects),
    forward_dynamics_torques = aba(tau), forward_dynamics_jacobian = computeABADerivatives at
    tau = 0 (the tests above compare dynamics and the Jacobian kernels composed here)."""
    tree, mod = trees[case]
    n, p = len(tree), mod.DEFAULT_PARAMS
    peer = robots_peers.pinocchio_model(tree)
    for q, v, tau, a in _states(*case):
        out = np.zeros(n)
        mod.inverse_dynamics.py_func(q, v, a, 0.0, p, out)
        assert _rel(out, robots_peers.rnea(peer, q, v, a)) < RTOL
        mod.gravity_forces.py_func(q, 0.0, p, out)
        assert _rel(out, robots_peers.rnea(peer, q, np.zeros(n), np.zeros(n))) < RTOL
        mod.bias_forces.py_func(q, v, 0.0, p, out)
        assert _rel(out, robots_peers.rnea(peer, q, v, np.zeros(n))) < RTOL
        assert mod.forward_dynamics_torques.py_func(q, v, tau, 0.0, p, np.zeros((n, n)), out) == 0
        assert _rel(out, robots_peers.aba(peer, q, v, tau)) < RTOL
        H, W, Jq, Jqd = (np.zeros((n, n)) for _ in range(4))
        assert mod.forward_dynamics_jacobian.py_func(q, v, 0.0, p, H, out, Jq, Jqd, W) == 0
        dq, dv = robots_peers.aba_derivatives(peer, q, v, np.zeros(n))
        assert _rel(out, robots_peers.aba(peer, q, v, np.zeros(n))) < RTOL
        assert _rel(Jq, dq) < RTOL and _rel(Jqd, dv) < RTOL
