"""Forward sensitivities (simulate(sensitivities=[...]), steppers/sensitivity/) against central
differences of simulate's own runs, for every method that has them, on the double pendulum, a
damped model with an input force, a 3D chain built from bodies and a random tree of joints; the
q0/v0 columns of one step against linear.step_jacobian; the parameter-derivative kernels against
central differences of the kernels they differentiate; bad input; and a module generated without
sensitivities has none of their kernels."""

import json

import numpy as np
import pytest

import lagrange_gen as lg
from lagrange_gen.analysis.random_trees import random_tree
from lagrange_gen.codegen import generate_model
from lagrange_gen.codegen.generate import generate_text
from lagrange_gen.errors import SimulationError
from lagrange_gen.linear.step_derivatives import step_jacobian
from lagrange_gen.model.model_file import load_model
from lagrange_gen.run.loader import import_generated
from lagrange_gen.steppers.sensitivity import SENSITIVITY_METHODS
from lg_test_support import MODELS_DIR

#: Agreement of a sensitivity with the central difference of step EPS (relative to the largest
#: entry of the difference quotient): the difference quotient's own error is O(EPS^2) plus the
#: Newton tolerance over EPS (~1e-8 for the partitioned methods' simplified Newton).
RTOL = 1e-6
EPS = 1e-6

DAMPED = '''
import sympy as sp
from lagrange_gen import Model, coordinates, parameters, inputs
x, th = coordinates("x th")
M, m, l, k, c, d, g = parameters("M m l k c d g", defaults=(1.0, 0.5, 0.8, 4.0, 0.3, 0.2, 9.81))
u = inputs("u", defaults=0.5)
T = (M + m) * x.d**2 / 2 + m * l * x.d * th.d * sp.cos(th) + m * l**2 * th.d**2 / 2
V = k * x**2 / 2 + k * x**4 / 8 - m * g * l * sp.cos(th)
model = Model("damped_cart", coords=[x, th], T=T, V=V, inputs=[u],
              dissipation=c * x.d**2 / 2 + d * th.d**2 / 2, forces={x: u * sp.cos(th)})
'''

#: Two rigid bodies in 3D (sympy.physics.mechanics, lg.kinetic_energy: the graph path, with the
#: recursive kernels) whose masses, inertias, centre of mass and link length are parameters.
BODIES = '''
import sympy.physics.mechanics as me
import lagrange_gen as lg
q1, q2, q3 = me.dynamicsymbols("q1 q2 q3")
m1, m2, l1, c2, I1, I2, g = lg.parameters("m1 m2 l1 c2 I1 I2 g",
                                          defaults=(1.2, 0.8, 0.6, 0.3, 0.05, 0.02, 9.81))
N = me.ReferenceFrame("N")
A = N.orientnew("A", "Axis", [q1, N.z])
B = A.orientnew("B", "Axis", [q2, A.y])
C = B.orientnew("C", "Axis", [q3, B.x])
O = me.Point("O"); O.set_vel(N, 0)
P = O.locatenew("P", -l1 * B.z)
G2 = P.locatenew("G2", -c2 * C.z + 0.1 * C.x)
G1 = O.locatenew("G1", -0.5 * l1 * B.z)
link1 = me.RigidBody("link1", G1, B, m1, (me.inertia(B, I1, I1, 0.3 * I1), G1))
link2 = me.RigidBody("link2", G2, C, m2, (me.inertia(C, I2, 1.5 * I2, 0.5 * I2, 0.1 * I2), G2))
bodies = [link1, link2]
model = lg.Model("bodies_3d", coords=[q1, q2, q3], T=lg.kinetic_energy(N, bodies),
                 V=lg.gravity_potential(N, -g * N.z, bodies), frame=N)
'''


def _tree_file(path, name, tree):
    path.write_text("from lagrange_gen.model.joint_tree import model_from_tree\n\n"
                    f"TREE = {json.dumps(tree)}\n\nmodel = model_from_tree({name!r}, TREE, g=9.81)\n")
    return path


@pytest.fixture(scope="module")
def models(tmp_path_factory):
    """{label: (module generated with sensitivities, q0, v0, parameters to differentiate)}."""
    out = tmp_path_factory.mktemp("sensitivities")
    damped = out / "damped_cart.py"
    damped.write_text(DAMPED)
    bodies = out / "bodies_3d.py"
    bodies.write_text(BODIES)
    tree = _tree_file(out / "random_tree_3.py", "random_tree_3", random_tree(np.random.default_rng(3), 3))
    cases = {"double_pendulum": (MODELS_DIR / "double_pendulum.py", {}, [0.5, 1.0], [0.0, 0.3],
                                 ["l2", "m2"]),
             "damped_cart": (damped, {}, [0.2, 0.4], [0.1, -0.2], ["c", "l", "u"]),
             "driven_pendulum": (MODELS_DIR / "driven_pendulum.py", {}, [2.9], [0.1], ["w", "a", "l"]),
             "bodies_3d": (bodies, {}, [0.3, 0.5, -0.2], [0.1, -0.2, 0.3], ["m2", "I2", "c2", "l1"]),
             "spatial_chain_3": (MODELS_DIR / "spatial_chain.py", {"n": 3}, [0.3, -0.4, 0.5],
                                 [0.2, 0.1, -0.3], ["g"]),
             "random_tree_3": (tree, {}, [0.2, -0.3, 0.1], [0.1, 0.2, 0.0], ["g"])}
    built = {}
    for label, (path, options, q0, v0, names) in cases.items():
        result = generate_model(path, out / "gen", options=options, sensitivities=True)
        built[label] = (import_generated(result.path), np.array(q0), np.array(v0), names)
    return built


def _run(module, method, q0, v0, params=None, **extra):
    return lg.simulate(module, method, q0, v0, t_end=0.3, h=0.01, params=params, save_every=3,
                       **extra)


def _state(traj):
    return np.hstack((traj.q, traj.v))


def _rel(a, b):
    return float(np.abs(a - b).max() / max(np.abs(b).max(), 1e-12))


def _central(module, method, q0, v0, name, direction=None):
    """(S, 2n) central difference of simulate's saved states in parameter ``name`` or along
    ``direction`` (2n,) of the initial state (name None)."""
    if name is not None:
        value = float(module.DEFAULT_PARAMS[list(module.PARAMS).index(name)])
        step = EPS * max(1.0, abs(value))
        plus = _run(module, method, q0, v0, {name: value + step})
        minus = _run(module, method, q0, v0, {name: value - step})
    else:
        n = len(q0)
        step = EPS
        plus = _run(module, method, q0 + step * direction[:n], v0 + step * direction[n:])
        minus = _run(module, method, q0 - step * direction[:n], v0 - step * direction[n:])
    return (_state(plus) - _state(minus)) / (2 * step)


LABELS = ("double_pendulum", "damped_cart", "driven_pendulum", "bodies_3d", "spatial_chain_3", "random_tree_3")
#: Models built from bodies share their kernels' kind: one method of each family runs on them.
GRAPH_LABELS = ("bodies_3d", "spatial_chain_3", "random_tree_3")


@pytest.mark.parametrize("method", SENSITIVITY_METHODS)
@pytest.mark.parametrize("label", LABELS)
def test_sensitivities_equal_central_differences(models, label, method):
    module, q0, v0, names = models[label]
    if label in GRAPH_LABELS and method not in ("midpoint", "rk4", "verlet"):
        pytest.skip("the graph models: one method of each kind (their kernels are shared)")
    traj = _run(module, method, q0, v0, sensitivities=names + ["q0", "v0"])
    plain = _run(module, method, q0, v0)
    assert _rel(_state(traj), _state(plain)) < 1e-10        # the same run
    for name in names:
        assert traj.sensitivity(name).shape == (len(traj.t), 2 * len(q0))
        assert _rel(traj.sensitivity(name), _central(module, method, q0, v0, name)) < RTOL, name
    rng = np.random.default_rng(0)
    n = len(q0)
    for name, block in (("q0", slice(0, n)), ("v0", slice(n, 2 * n))):
        S = traj.sensitivity(name)
        assert S.shape == (len(traj.t), 2 * n, n)
        direction = np.zeros(2 * n)
        direction[block] = rng.normal(size=n)
        assert _rel(S @ direction[block], _central(module, method, q0, v0, None, direction)) < RTOL


@pytest.mark.parametrize("method", SENSITIVITY_METHODS)
def test_one_step_equals_step_jacobian(models, method):
    """d(q1, v1)/d(q0, v0) after one step is linear.step_jacobian's Fx (its own derivation)."""
    module, q0, v0, _ = models["damped_cart"]
    traj = lg.simulate(module, method, q0, v0, t_end=0.01, h=0.01, sensitivities=["q0", "v0"])
    _, _, Fx, _ = step_jacobian(module, method, 0.01, q0, v0, u=module.DEFAULT_PARAMS[-1:])
    S = np.concatenate((traj.sensitivity("q0")[-1], traj.sensitivity("v0")[-1]), axis=1)
    assert _rel(S, Fx) < 1e-9


@pytest.mark.parametrize("label", ["double_pendulum", "bodies_3d", "spatial_chain_3"])
def test_parameter_kernels_equal_central_differences_of_the_kernels(models, label):
    module, q0, v0, _ = models[label]
    n, p = module.N_COORDS, module.DEFAULT_PARAMS.copy()
    w = np.linspace(0.3, -0.4, n)

    def rhs(p):
        H, out = np.zeros((n, n)), np.zeros(n)
        module.dynamics(q0, v0, 0.0, p, H, out)
        return out, H @ w

    def mom(p):
        out = np.zeros(n)
        module.momentum_rate(q0, v0, 0.0, p, out)
        return out

    Jr, Jm, Jh = (np.zeros((n, len(p))) for _ in range(3))
    module.rhs_dp(q0, v0, 0.0, p, Jr)
    module.momentum_rate_dp(q0, v0, 0.0, p, Jm)
    module.mass_matvec_dp(q0, w, 0.0, p, Jh)
    for j in range(len(p)):
        e = np.zeros(len(p))
        e[j] = 1e-6 * max(1.0, abs(p[j]))
        (r1, h1), (r0, h0) = rhs(p + e), rhs(p - e)
        scale = 2 * e[j]
        assert np.allclose(Jr[:, j], (r1 - r0) / scale, rtol=1e-6, atol=1e-7)
        assert np.allclose(Jh[:, j], (h1 - h0) / scale, rtol=1e-6, atol=1e-7)
        assert np.allclose(Jm[:, j], (mom(p + e) - mom(p - e)) / scale, rtol=1e-6, atol=1e-7)


def test_a_module_without_sensitivities_has_none_of_their_kernels():
    model = load_model(MODELS_DIR / "double_pendulum.py")
    plain, _, _ = generate_text(model, methods=["midpoint", "rk4"])
    with_them, _, _ = generate_text(model, methods=["midpoint", "rk4"], sensitivities=True)
    for name in ("rhs_dp", "momentum_rate_dp", "mass_matvec_dp", "transport_dp"):
        assert f"def {name}(" not in plain and f"def {name}(" in with_them
    assert "sensitivities" not in plain.split("OPTIONS = ", 1)[1].split("\n", 1)[0]


def test_bad_input_is_one_line(models):
    module, q0, v0, _ = models["double_pendulum"]
    with pytest.raises(SimulationError, match="has no parameter 'l3'") as bad_name:
        _run(module, "midpoint", q0, v0, sensitivities=["l3"])
    with pytest.raises(SimulationError, match="dop853 has no sensitivities") as bad_method:
        lg.simulate(module, "dop853", q0, v0, t_end=0.1, sensitivities=["l2"])
    for exc in (bad_name, bad_method):
        assert "\n" not in str(exc.value)
    with pytest.raises(KeyError, match="was not asked for"):
        _run(module, "rk4", q0, v0, sensitivities=["l2"]).sensitivity("m2")


def test_a_model_file_is_regenerated_with_sensitivities_when_asked(tmp_path):
    """A module generated without them gains them (keeping its methods), and keeps them."""
    from lagrange_gen.codegen.keys import read_header
    path = MODELS_DIR / "double_pendulum.py"
    target = generate_model(path, tmp_path, methods=["rk4"]).path
    assert "sensitivities" not in read_header(target)["OPTIONS"]
    traj = lg.simulate(path, "rk4", [0.5, 1.0], [0.0, 0.3], t_end=0.05, h=0.01, out_dir=tmp_path,
                       sensitivities=["g"])
    assert traj.sensitivity("g").shape == (6, 4)
    traj.save(tmp_path / "run.npz")                       # the sensitivities travel with it
    assert np.array_equal(lg.Trajectory.load(tmp_path / "run.npz").sensitivity("g"),
                          traj.sensitivity("g"))
    assert read_header(target)["OPTIONS"] == {"build": {}, "methods": ["rk4"], "sensitivities": True}
    lg.simulate(path, "rk4", [0.5, 1.0], [0.0, 0.3], t_end=0.05, h=0.01, out_dir=tmp_path)
    assert read_header(target)["OPTIONS"]["sensitivities"] is True
