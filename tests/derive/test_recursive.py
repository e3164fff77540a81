"""Recursive algorithms over a tree of joints (model/joint_form.py, derive/recursive.py): on small
random spatial trees (revolute and prismatic joints, full inertias) ABA, RNEA and the derivative
of the accelerations through RNEA equal the H + Cholesky path of the graph and an independent
plain-sympy Lagrange derivation (explicit rotation matrices); models that do not fit keep the
old path."""

import dataclasses

import numpy as np
import pytest
import sympy as sp

from lagrange_gen import Model, parameters
from lagrange_gen.analysis.random_trees import random_tree
from lagrange_gen.codegen.forward import forward_source, uses_aba
from lagrange_gen.derive import derive
from lagrange_gen.derive.recursive import recursive_dynamics
from lagrange_gen.model.bodies import gravity_potential, kinetic_energy
from lagrange_gen.model.joint_form import joint_form
from lagrange_gen.model.joint_tree import model_from_tree, tree_bodies
from lagrange_gen.model.symbols import t

#: (bodies, seed): prismatic joints and branching among them (seeds 0 and 1: two prismatic each)
CASES = [(3, 2), (4, 0), (4, 1)]
RTOL = 1e-12


def _rodrigues(axis, angle):
    k = sp.Matrix(axis) / sp.sqrt(sum(sp.Float(a) ** 2 for a in axis))
    K = sp.Matrix([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return sp.eye(3) + sp.sin(angle) * K + (1 - sp.cos(angle)) * K * K


def plain_lagrange(tree, g=9.81):
    """(H(q), rhs(q, qd)) numpy functions from L = T - V written with explicit rotation matrices
    (world from body) and mass-centre positions: no lagrange_gen derivation, no mechanics."""
    n = len(tree)
    q, qd = sp.symbols(f"q0:{n}"), sp.symbols(f"qd0:{n}")
    R_of, p_of, L = {}, {}, sp.S.Zero
    for i, joint in enumerate(tree):
        R_p = sp.eye(3) if joint["parent"] < 0 else R_of[joint["parent"]]
        p_p = sp.zeros(3, 1) if joint["parent"] < 0 else p_of[joint["parent"]]
        J = p_p + R_p * sp.Matrix(joint["origin"])
        if joint["type"] == "revolute":
            R, origin = R_p * _rodrigues(joint["axis"], q[i]), J
        else:
            unit = sp.Matrix(joint["axis"]) / sp.sqrt(sum(sp.Float(a) ** 2 for a in joint["axis"]))
            R, origin = R_p, J + R_p * unit * q[i]
        R_of[i], p_of[i] = R, origin
        c = origin + R * sp.Matrix(joint["com"])
        vel = c.jacobian(q) * sp.Matrix(qd)
        W = R.T * sum((R.diff(q[j]) * qd[j] for j in range(n)), sp.zeros(3, 3))
        w = sp.Matrix([W[2, 1], W[0, 2], W[1, 0]])
        ixx, iyy, izz, ixy, iyz, izx = joint["inertia"]
        I = sp.Matrix([[ixx, ixy, izx], [ixy, iyy, iyz], [izx, iyz, izz]])
        L += joint["mass"] * vel.dot(vel) / 2 + (w.T * I * w)[0] / 2 - joint["mass"] * g * c[2]
    dL_dqd = sp.Matrix([L.diff(x) for x in qd])
    H = dL_dqd.jacobian(qd)
    rhs = sp.Matrix([L.diff(x) for x in q]) - dL_dqd.jacobian(q) * sp.Matrix(qd)
    fH, frhs = sp.lambdify([q], H, cse=True), sp.lambdify([q, qd], rhs, cse=True)
    return lambda x: np.array(fH(x), dtype=float), lambda x, v: np.array(frhs(x, v), dtype=float).ravel()


@pytest.fixture(scope="module", params=CASES, ids=[f"{n}bodies-seed{s}" for n, s in CASES])
def case(request):
    n, seed = request.param
    tree = random_tree(np.random.default_rng(seed), n, prismatic=0.4)
    return tree, derive(model_from_tree(f"tree{n}_{seed}", tree))


def _evaluate(dyn, exprs):
    """f(q, qd, other (n,)) -> values of ``exprs`` (native, over q, qd, qdd or w, p, t)."""
    o = dyn.ops
    args = o.symbols(dyn.q + dyn.qd + dyn.aux["qdd"] + dyn.aux["w"] + dyn.params + [t])
    f = o.graph.evaluator(args, list(exprs))
    p = [9.81]
    return lambda q, v, x: np.asarray(f([*q, *v, *x, *x, *p, 0.0]), dtype=float)


def _rel(a, b):
    return float(np.abs(np.asarray(a) - np.asarray(b)).max() / max(np.abs(b).max(), 1e-12))


def test_the_cases_have_prismatic_joints_and_branching():
    trees = [random_tree(np.random.default_rng(s), n, prismatic=0.4) for n, s in CASES]
    assert any(j["type"] == "prismatic" for tree in trees for j in tree)
    assert any(len({j["parent"] for j in tree}) < len(tree) for tree in trees)


def test_aba_and_rnea_equal_the_graph_path(case):
    tree, dyn = case
    assert dyn.recursive is not None
    n, o = dyn.n, dyn.ops
    w, qdd = o.symbols(dyn.aux["w"]), o.symbols(dyn.aux["qdd"])
    aba, _ = dyn.recursive.forward_dynamics(w)
    rnea = dyn.recursive.inverse_dynamics(qdd)
    f = _evaluate(dyn, [*aba, *rnea, *dyn.native["H"], *dyn.native["rhs"]])
    rng = np.random.default_rng(7)
    for _ in range(2):
        q, v, x = rng.uniform(-1.5, 1.5, (3, n))
        values = f(q, v, x)
        acc, tau = values[:n], values[n:2 * n]
        H, rhs = values[2 * n:2 * n + n * n].reshape(n, n), values[2 * n + n * n:]
        assert _rel(acc, np.linalg.solve(H, rhs + x)) < RTOL          # x as joint torques
        assert _rel(tau, H @ x - rhs) < RTOL                           # x as accelerations


def test_aba_and_rnea_equal_plain_sympy_on_a_3_body_tree():
    tree = random_tree(np.random.default_rng(1), 3, prismatic=0.5)
    assert {j["type"] for j in tree} == {"revolute", "prismatic"}
    dyn = derive(model_from_tree("tree3_1", tree))
    n, o = dyn.n, dyn.ops
    aba, _ = dyn.recursive.forward_dynamics(o.symbols(dyn.aux["w"]))
    f = _evaluate(dyn, [*aba, *dyn.recursive.inverse_dynamics(o.symbols(dyn.aux["qdd"]))])
    H_ref, rhs_ref = plain_lagrange(tree)
    q, v, x = np.random.default_rng(7).uniform(-1.5, 1.5, (3, n))
    values = f(q, v, x)
    assert _rel(values[:n], np.linalg.solve(H_ref(q), rhs_ref(q, v) + x)) < 1e-10
    assert _rel(values[n:], H_ref(q) @ x - rhs_ref(q, v)) < 1e-10


def test_acceleration_derivatives_through_rnea_equal_the_graph_path(case):
    """-H^-1 d(RNEA)/dx at the solved qdd equals H^-1 (d rhs/dx - d(H w)/dq) of the graph."""
    _, dyn = case
    n, o, graph = dyn.n, dyn.ops, dyn.ops.graph
    q_s, qd_s = o.symbols(dyn.q), o.symbols(dyn.qd)
    rnea = dyn.recursive.inverse_dynamics(o.symbols(dyn.aux["qdd"]))
    d_rnea = graph.jacobian(rnea, q_s + qd_s)
    old = [*dyn.jac.native("drhs_dq"), *dyn.jac.native("drhs_dqd"), *dyn.jac.native("dHw_dq")]
    aba, _ = dyn.recursive.forward_dynamics()
    f_acc = _evaluate(dyn, aba + list(dyn.native["H"]))
    f = _evaluate(dyn, [e for row in d_rnea for e in row] + old)
    rng = np.random.default_rng(8)
    q, v = rng.uniform(-1.5, 1.5, (2, n))
    values = f_acc(q, v, np.zeros(n))
    acc, H = values[:n], values[n:].reshape(n, n)
    values = f(q, v, acc)                        # qdd and w both the solved accelerations
    d_id = values[:2 * n * n].reshape(n, 2 * n)
    drhs_dq, drhs_dqd, dHw_dq = values[2 * n * n:].reshape(3, n, n)
    ours = -np.linalg.solve(H, d_id)
    graph_path = np.linalg.solve(H, np.hstack((drhs_dq - dHw_dq, drhs_dqd)))
    assert _rel(ours, graph_path) < 1e-11


def test_generated_forward_dynamics_is_aba_and_agrees(case):
    """The emitted ABA, ABA with torques and RNEA Jacobian kernels (their Python functions, no
    numba compile) give the accelerations and derivatives of dynamics + solve."""
    _, dyn = case
    assert uses_aba(dyn)
    text = forward_source(dyn)
    assert "articulated-body algorithm" in text and "def inverse_dynamics_jacobian(" in text
    namespace = {}      # the module's names the kernels use; njit left out: plain Python
    exec("import math\nimport numpy as np\nSINGULAR_RTOL = 1e-13\nOK, SINGULAR_MASS = 0, 1\n"
         f"N_COORDS = {dyn.n}\nKERNEL_OPTIONS = {{}}\ndef njit(**options):\n    return lambda f: f\n" + text,
         namespace)
    n = dyn.n
    rng = np.random.default_rng(9)
    q, v, tau = rng.uniform(-1.5, 1.5, (3, n))
    p = np.array([9.81])
    H, rhs = _graph_dynamics(dyn, q, v)
    qdd = np.zeros(n)
    assert namespace["forward_dynamics"](q, v, 0.0, p, None, qdd) == 0
    assert _rel(qdd, np.linalg.solve(H, rhs)) < RTOL
    with_tau = np.zeros(n)
    assert namespace["forward_dynamics_torques"](q, v, tau, 0.0, p, None, with_tau) == 0
    assert _rel(with_tau, np.linalg.solve(H, rhs + tau)) < RTOL
    Jq, Jqd = np.zeros((n, n)), np.zeros((n, n))
    namespace["inverse_dynamics_jacobian"](q, v, qdd, 0.0, p, Jq, Jqd)
    eps = 1e-6
    numeric = np.array([(_accelerations(dyn, q + eps * e, v) - _accelerations(dyn, q - eps * e, v)) / (2 * eps)
                        for e in np.eye(n)]).T
    assert np.allclose(-np.linalg.solve(H, Jq), numeric, rtol=1e-6, atol=1e-7)


def _graph_dynamics(dyn, q, v):
    n = dyn.n
    values = _evaluate(dyn, [*dyn.native["H"], *dyn.native["rhs"]])(q, v, np.zeros(n))
    return values[:n * n].reshape(n, n), values[n * n:]


def _accelerations(dyn, q, v):
    H, rhs = _graph_dynamics(dyn, q, v)
    return np.linalg.solve(H, rhs)


# ------------------------------------------------------------------ models that do not fit


def _tree_model(extra_T=0, **options):
    tree = random_tree(np.random.default_rng(0), 3, prismatic=0.4)
    g = parameters("g", defaults=(9.81,))
    N, O, q, bodies = tree_bodies(tree)
    T = kinetic_energy(N, bodies)
    model = Model("misfit", coords=q, T=T + extra_T(q) if extra_T else T,
                  V=gravity_potential(N, -g * N.z, bodies), **options)
    return model


def test_energy_with_extra_terms_keeps_the_old_path():
    model = _tree_model(lambda q: sp.Rational(1, 2) * q[0].diff() ** 2)
    dyn = derive(model)
    assert joint_form(model.T) is None and dyn.recursive is None and not uses_aba(dyn)
    assert "articulated-body" not in forward_source(dyn)


def test_constrained_tree_keeps_the_old_path():
    model = _tree_model()
    q = model.coords
    constrained = Model("constrained", coords=q, T=model.T, V=model.V, constraints=[q[0] - q[1]])
    assert joint_form(constrained.T) is not None
    assert derive(constrained).recursive is None


def test_a_tree_that_does_not_reproduce_the_energy_is_refused():
    """The numeric check can fail: a link with the wrong mass is not used."""
    model = _tree_model()
    links = joint_form(model.T)
    dyn = derive(model)
    assert dyn.recursive is not None
    wrong = [dataclasses.replace(links[0], mass=2 * links[0].mass)] + links[1:]
    from lagrange_gen.derive.structured import graph_model, import_expressions, derive_lagrangian_graph
    plain = graph_model(model)
    o, (T, V, D) = import_expressions(plain, {}, [plain.T, plain.V, plain.dissipation])
    parts = derive_lagrangian_graph(plain, o, T, V, D, [0] * len(model.coords))
    qdd = o.symbols(dyn.aux["qdd"])
    assert recursive_dynamics(links, o, plain, T, parts, qdd, {}) is not None
    assert recursive_dynamics(wrong, o, plain, T, parts, qdd, {}) is None


# ------------------------------------------------- Newton Jacobians from the recursive programs

#: The column kernels and what each differentiates (graph fields, or H w for mass_matvec_dq).
COLUMN_KERNELS = ("rhs_jacobian", "mass_matvec_dq", "momentum_rate_jacobian")


def _column_matrices(dyn, columns, q, v, w, params=(9.81,)):
    """{output name: (n, n) matrix} of ``columns`` [(name, seeds, column)] at (q, v, w): column
    k evaluated with seed k = 1, the others 0."""
    o, n = dyn.ops, dyn.n
    out = {}
    for name, seeds, column in columns:
        args = o.symbols(dyn.q + dyn.qd + dyn.aux["w"] + dyn.params + [t]) + list(seeds)
        f = o.graph.evaluator(args, list(column))
        out[name] = np.array([f([*q, *v, *w, *params, 0.0, *np.eye(n)[k]]) for k in range(n)], dtype=float).T
    return out


def _differenced(dyn, kernel, q, v, w, eps=1e-6):
    """The same matrices by central differences of the graph's rhs, momentum_rate or H w."""
    o, n = dyn.ops, dyn.n
    if kernel == "mass_matvec_dq":
        Hw = o.graph.tangents(dyn.jac._p["p"], dict(zip(o.symbols(dyn.qd), o.symbols(dyn.aux["w"]))))
        f, names = _evaluate(dyn, Hw), ("out_mat",)
    else:
        field = "rhs" if kernel == "rhs_jacobian" else "momentum_rate"
        f, names = _evaluate(dyn, list(dyn.native[field])), ("Jq", "Jqd")
    out = {}
    for name, moving in zip(names, ("q", "qd")):
        def at(x):
            return f(x, v, w) if moving == "q" else f(q, x, w)
        x0 = q if moving == "q" else v
        out[name] = np.array([(at(x0 + eps * e) - at(x0 - eps * e)) / (2 * eps) for e in np.eye(n)]).T
    return out


def _damped_tree_model():
    """A 3D tree (prismatic and revolute joints, full inertias) with viscous damping and a
    velocity-dependent force besides gravity: Q depends on q and qd."""
    tree = random_tree(np.random.default_rng(4), 4, prismatic=0.4)
    from sympy.physics.mechanics import dynamicsymbols
    me_time = dynamicsymbols._t                  # the time of the joints' dynamicsymbols
    g, c = parameters("g c", defaults=(9.81, 0.3))
    N, O, q, bodies = tree_bodies(tree)
    qd = [x.diff(me_time) for x in q]
    return Model("damped_tree", coords=q, T=kinetic_energy(N, bodies),
                 V=gravity_potential(N, -g * N.z, bodies),
                 dissipation=c * sum(x ** 2 for x in qd) / 2,
                 forces=[sp.sin(q[1]) * qd[0], 0, -0.2 * qd[2] * sp.cos(q[0]), 0])


@pytest.mark.parametrize("kernel", COLUMN_KERNELS)
def test_recursive_jacobian_columns_equal_the_graph_columns(case, kernel):
    """Each Newton Jacobian as tangents of RNEA equals the Lagrangian graph's tangents (1e-12)
    and central differences of the graph's rhs, momentum_rate or H w, at two random states."""
    _, dyn = case
    n = dyn.n
    graph_columns = dyn.jac.columns(kernel)
    recursive = dyn.recursive.columns(kernel, graph_columns[0][1], dyn.ops.symbols(dyn.aux["w"]))
    assert [c[0] for c in recursive] == [c[0] for c in graph_columns]
    rng = np.random.default_rng(10)
    for _ in range(2):
        q, v, w = rng.uniform(-1.5, 1.5, (3, n))
        ours = _column_matrices(dyn, recursive, q, v, w)
        reference = _column_matrices(dyn, graph_columns, q, v, w)
        numeric = _differenced(dyn, kernel, q, v, w)
        for name in reference:
            assert _rel(ours[name], reference[name]) < RTOL, name
            assert np.allclose(ours[name], numeric[name], rtol=1e-6, atol=1e-7), name


def test_recursive_jacobian_columns_with_damping_and_velocity_forces():
    """Q = F - dD/dqd depends on q and qd: its tangents enter rhs_jacobian and
    momentum_rate_jacobian through tau_model, as in the graph's."""
    dyn = derive(_damped_tree_model())
    assert dyn.recursive is not None
    n = dyn.n
    q, v, w = np.random.default_rng(11).uniform(-1.5, 1.5, (3, n))
    for kernel in COLUMN_KERNELS:
        graph_columns = dyn.jac.columns(kernel)
        recursive = dyn.recursive.columns(kernel, graph_columns[0][1], dyn.ops.symbols(dyn.aux["w"]))
        ours = _column_matrices(dyn, recursive, q, v, w, (9.81, 0.3))
        reference = _column_matrices(dyn, graph_columns, q, v, w, (9.81, 0.3))
        for name in reference:
            assert _rel(ours[name], reference[name]) < RTOL, (kernel, name)


def test_emitted_column_kernels_agree_and_come_from_rnea_where_shorter(case):
    """The column kernels a tree model is generated with (their Python, no numba compile):
    rhs_jacobian and mass_matvec_dq from RNEA (fewer operations than the graph's on these
    trees), each equal to the Lagrangian graph's tangents to 1e-12."""
    from lagrange_gen.codegen.emit import render_kernel
    from lagrange_gen.codegen.printer import Inputs
    from lagrange_gen.codegen.spec import RECURSIVE_SOURCES, jacobian_columns, kernel_table
    _, dyn = case
    n = dyn.n
    table, inputs = kernel_table(dyn), Inputs(dyn)
    rng = np.random.default_rng(12)
    q, v, w = rng.uniform(-1.5, 1.5, (3, n))
    p = np.array([9.81])
    for kernel in COLUMN_KERNELS:
        _, source = jacobian_columns(dyn, kernel)
        if kernel != "momentum_rate_jacobian":
            assert source == RECURSIVE_SOURCES[kernel]
        spec = table[kernel]()
        namespace = {}
        exec(f"import math\nKERNEL_OPTIONS = {{}}\ndef njit(**options):\n    return lambda f: f\n"
             + render_kernel(spec, inputs).function, namespace)
        outputs = [np.zeros((n, n)) for _ in spec.columns]
        second = w if kernel == "mass_matvec_dq" else v
        namespace[kernel](q, second, 0.0, p, *outputs)
        reference = _column_matrices(dyn, dyn.jac.columns(kernel), q, v, w)
        for name, value in zip([c[0] for c in spec.columns], outputs):
            assert _rel(value, reference[name]) < RTOL, (kernel, name)


def _rnea_mass_kernels(dyn, q, v):
    """(H from mass_matrix, H and rhs from dynamics) of the RNEA-column kernels of a tree
    (recursive_mass_specs: emitted or not, by operation count), run as Python (no numba)."""
    from lagrange_gen.codegen.emit import render_kernel
    from lagrange_gen.codegen.printer import Inputs
    from lagrange_gen.codegen.spec import recursive_mass_specs
    n, inputs, namespace = dyn.n, Inputs(dyn), {}
    for kernel, (build, *_) in recursive_mass_specs(dyn).items():
        spec = build()
        assert spec.columns, kernel              # the loop over H's columns, not the graph's H
        exec(f"import math\nKERNEL_OPTIONS = {{}}\ndef njit(**options):\n    return lambda f: f\n"
             + render_kernel(spec, inputs).function, namespace)
    p = np.array([9.81, 0.3][:len(dyn.params)])
    H_alone, H, rhs = np.full((n, n), np.nan), np.full((n, n), np.nan), np.full(n, np.nan)
    namespace["mass_matrix"](q, 0.0, p, H_alone)
    namespace["dynamics"](q, v, 0.0, p, H, rhs)
    return H_alone, H, rhs


def test_emitted_mass_kernels_from_rnea_agree(case):
    """mass_matrix and dynamics of a tree from RNEA: H column by column by RNEA at rest, exactly
    symmetric, and rhs by the bias RNEA, equal to the graph's H and rhs to 1e-12."""
    _, dyn = case
    q, v = np.random.default_rng(13).uniform(-1.5, 1.5, (2, dyn.n))
    H_ref, rhs_ref = _graph_dynamics(dyn, q, v)
    H_alone, H, rhs = _rnea_mass_kernels(dyn, q, v)
    for matrix in (H_alone, H):
        assert np.array_equal(matrix, matrix.T) and _rel(matrix, H_ref) < RTOL
    assert _rel(rhs, rhs_ref) < RTOL


def test_rnea_dynamics_with_damping_and_velocity_forces():
    """rhs = Q - h - g by the bias RNEA where Q depends on q and qd (damping, a force)."""
    dyn = derive(_damped_tree_model())
    q, v = np.random.default_rng(14).uniform(-1.5, 1.5, (2, dyn.n))
    o = dyn.ops
    args = o.symbols(dyn.q + dyn.qd + dyn.params + [t])
    f = o.graph.evaluator(args, [*dyn.native["H"], *dyn.native["rhs"]])
    values = np.asarray(f([*q, *v, 9.81, 0.3, 0.0]), dtype=float)
    n = dyn.n
    _, H, rhs = _rnea_mass_kernels(dyn, q, v)
    assert _rel(H, values[:n * n].reshape(n, n)) < RTOL and _rel(rhs, values[n * n:]) < RTOL


def test_a_12_link_chain_takes_its_jacobians_and_mass_kernels_from_rnea():
    """On models/spatial_chain.py's 12-link chain RNEA's programs are shorter both in the text
    and per call: rhs_jacobian, mass_matvec_dq, mass_matrix and dynamics come from them;
    momentum_rate_jacobian stays the graph's (Hdot qd - tau(q, qd, 0) is longer)."""
    from lagrange_gen.codegen.spec import RECURSIVE_SOURCES, jacobian_columns, kernel_table
    from lagrange_gen.model.model_file import load_model
    from pathlib import Path
    dyn = derive(load_model(Path(__file__).parents[2] / "models" / "spatial_chain.py", n=12))
    sources = {k: jacobian_columns(dyn, k)[1] for k in COLUMN_KERNELS}
    assert sources == {**RECURSIVE_SOURCES, "momentum_rate_jacobian": ""}
    table = kernel_table(dyn)
    assert table["mass_matrix"]().columns and table["dynamics"]().columns


# ------------------------------------------------------- joints of several coordinates (ABA)


def _ball_or_floating_body_with_a_hinge(floating):
    """Body A on a ball joint at the fixed point O (Euler angles a, b, c: 'Body' XYZ) or free
    (x, y, z of its origin and the same angles: a floating base in one chart), body B on a hinge
    about A.y: one joint of 3 (6) coordinates and one of 1. Returns (model, plain (H, rhs))."""
    import sympy.physics.mechanics as me
    g = parameters("g", defaults=(9.81,))
    syms = me.dynamicsymbols("x y z a b c d" if floating else "a b c d")
    trans, (a, b, c, d) = (syms[:3], syms[3:]) if floating else ((0, 0, 0), syms)
    N, O = me.ReferenceFrame("N"), me.Point("O")
    O.set_vel(N, 0)
    A = N.orientnew("A", "Body", [a, b, c], "XYZ")
    Ao = O.locatenew("Ao", trans[0] * N.x + trans[1] * N.y + trans[2] * N.z) if floating else O
    GA = Ao.locatenew("GA", 0.05 * A.x + 0.3 * A.z)
    IA = (0.05, 0.04, 0.02, 0.003, -0.002, 0.001)
    body_A = me.RigidBody("A", GA, A, 2.0, (me.inertia(A, *IA), GA))
    B = A.orientnew("B", "Axis", [d, A.y])
    GB = Ao.locatenew("J", 0.6 * A.z).locatenew("GB", 0.2 * B.x + 0.1 * B.z)
    IB = (0.01, 0.02, 0.015, 0.001, 0.0, -0.002)
    body_B = me.RigidBody("B", GB, B, 1.0, (me.inertia(B, *IB), GB))
    model = Model("several", coords=list(syms), T=kinetic_energy(N, body_A, body_B),
                  V=gravity_potential(N, -g * N.z, body_A, body_B))

    # the same bodies with explicit rotation matrices, no mechanics and no lagrange_gen
    n = len(syms)
    q, qd = sp.symbols(f"q0:{n}"), sp.symbols(f"qd0:{n}")
    x = q[:3] if floating else (0, 0, 0)
    ea, eb, ec, ed = q[-4:]

    def rot(axis, angle):
        return _rodrigues([1 if k == axis else 0 for k in range(3)], angle)
    R_A = rot(0, ea) * rot(1, eb) * rot(2, ec)
    R_B = R_A * rot(1, ed)
    p_A = sp.Matrix(x)
    L = sp.S.Zero
    for R, c_body, m, (ixx, iyy, izz, ixy, iyz, izx) in (
            (R_A, p_A + R_A * sp.Matrix([0.05, 0, 0.3]), 2.0, IA),
            (R_B, p_A + R_A * sp.Matrix([0, 0, 0.6]) + R_B * sp.Matrix([0.2, 0, 0.1]), 1.0, IB)):
        vel = c_body.jacobian(q) * sp.Matrix(qd)
        W = R.T * sum((R.diff(q[j]) * qd[j] for j in range(n)), sp.zeros(3, 3))
        w = sp.Matrix([W[2, 1], W[0, 2], W[1, 0]])
        I = sp.Matrix([[ixx, ixy, izx], [ixy, iyy, iyz], [izx, iyz, izz]])
        L += m * vel.dot(vel) / 2 + (w.T * I * w)[0] / 2 - m * 9.81 * c_body[2]
    dL_dqd = sp.Matrix([L.diff(v) for v in qd])
    H = dL_dqd.jacobian(qd)
    rhs = sp.Matrix([L.diff(v) for v in q]) - dL_dqd.jacobian(q) * sp.Matrix(qd)
    fH, frhs = sp.lambdify([q], H, cse=True), sp.lambdify([q, qd], rhs, cse=True)
    return model, (lambda s: np.array(fH(s), dtype=float), lambda s, v: np.array(frhs(s, v), dtype=float).ravel())


@pytest.mark.parametrize("floating", [False, True], ids=["ball-joint", "floating-euler"])
def test_aba_over_joints_of_several_coordinates_equals_plain_sympy(floating):
    """A joint of k > 1 coordinates (S of k columns, depending on q) in ABA: D = S^T I^A S is
    k x k (its LDL^T pivots checked), I^a = I^A - U D^-1 U^T; accelerations and RNEA equal
    Lagrange's equations written with explicit rotation matrices."""
    import sympy.physics.mechanics as me
    model, (H_ref, rhs_ref) = _ball_or_floating_body_with_a_hinge(floating)
    links = joint_form(model.T)
    assert [len(link.coords) for link in links] == [6 if floating else 3, 1]
    dyn = derive(model)
    assert dyn.recursive is not None and uses_aba(dyn)
    n, o = dyn.n, dyn.ops
    aba, pivots = dyn.recursive.forward_dynamics(o.symbols(dyn.aux["w"]))
    assert len(pivots) == n
    rnea = dyn.recursive.inverse_dynamics(o.symbols(dyn.aux["qdd"]))
    f = _evaluate(dyn, [*aba, *rnea, *pivots])
    # the reference's convention: sympy's 'Body' XYZ is R = Rx(a) Ry(b) Rz(c)
    N = me.ReferenceFrame("N")
    angles = (0.3, -0.7, 1.1)
    A = N.orientnew("A", "Body", list(angles), "XYZ")
    R = _rodrigues([1, 0, 0], angles[0]) * _rodrigues([0, 1, 0], angles[1]) * _rodrigues([0, 0, 1], angles[2])
    assert np.allclose(np.array(N.dcm(A), dtype=float), np.array(R, dtype=float), atol=1e-15)
    rng = np.random.default_rng(11)
    for _ in range(3):
        q, v, x = rng.uniform(-1.2, 1.2, (3, n))
        values = f(q, v, x)
        acc, tau, d = values[:n], values[n:2 * n], values[2 * n:]
        H, rhs = H_ref(q), rhs_ref(q, v)
        assert _rel(acc, np.linalg.solve(H, rhs + x)) < 1e-11
        assert _rel(tau, H @ x - rhs) < 1e-11
        assert (d > 0).all()
