"""Models built from bodies (model/bodies.py) derived through the expression graph
(derive/structured.py): the same equations as the written-out expression path, on a spatial chain
with full inertia tensors; the robotics kernels; what users write with sympy.physics.mechanics
(v2pt_theory on every point, a constraint on top of a body model); bad input."""

from pathlib import Path

import numpy as np
import pytest
import sympy as sp
import sympy.physics.mechanics as me

import lagrange_gen as lg
from lagrange_gen import Model, ModelError, parameters
from lagrange_gen.derive import derive
from lagrange_gen.derive.structured import graph_model
from lagrange_gen.model.intermediates import Intermediate, expand_intermediates


def chain(n, v2pt=False, constraint=False):
    """A spatial chain: joint axes alternating z / y, offsets in two directions, full inertias."""
    qs = me.dynamicsymbols(f"q0:{n}")
    g = parameters("g", defaults=(9.81,))
    N = me.ReferenceFrame("N")
    O = me.Point("O")
    O.set_vel(N, 0)
    bodies, parent, joint = [], N, O
    for i in range(n):
        A = parent.orientnew(f"A{i}", "Axis", (qs[i], parent.z if i % 2 == 0 else parent.y))
        G = joint.locatenew(f"G{i}", 0.1 * A.x + 0.02 * A.y + 0.25 * A.z)
        if v2pt:
            G.v2pt_theory(joint, N, A)
        inertia = me.inertia(A, 0.02 + 0.001 * i, 0.03, 0.015, 0.001, -0.002, 0.0015)
        bodies.append(me.RigidBody(f"B{i}", G, A, 1.0 + 0.1 * i, (inertia, G)))
        nxt = joint.locatenew(f"J{i + 1}", 0.5 * A.z + 0.05 * A.x)
        if v2pt:
            nxt.v2pt_theory(joint, N, A)
        joint, parent = nxt, A
    extra = dict(constraints=[qs[0] - qs[1] / 2]) if constraint else {}
    return Model(f"chain{n}", coords=qs, T=lg.kinetic_energy(N, bodies),
                 V=lg.gravity_potential(N, -g * N.z, bodies), **extra)


def _numeric(matrix, values):
    return np.array(matrix.xreplace({s: values[s.name] for s in matrix.free_symbols}).evalf(), dtype=float)


@pytest.fixture(scope="module")
def both_ways():
    structured = derive(chain(3))
    written = derive(graph_model(chain(3), expand_all=True))
    return structured, written


def _state(dyn, seed=3):
    rng = np.random.default_rng(seed)
    values = {s.name: v for s, v in zip(dyn.q + dyn.qd, rng.uniform(-1.5, 1.5, 2 * dyn.n))}
    values["g"] = 9.81
    return values


def _native_values(dyn, matrix, values):
    """Entries of a native matrix at ``values`` {name: number}, by the backend's evaluator."""
    args = dyn.q + dyn.qd + dyn.params + dyn.aux["w"]
    f = dyn.ops.lambdify(dyn.ops.symbols(args), list(matrix))
    return f([values.get(s.name, 0.5) for s in args])


def test_graph_and_written_out_derivations_agree(both_ways):
    structured, written = both_ways
    assert structured.ops.graph is not None and not hasattr(written.ops, "graph")
    values = _state(structured)
    for field in ("H", "h", "g", "rhs", "momentum_rate", "power"):
        a = _native_values(structured, structured.native[field], values)
        b = _native_values(written, written.native[field], values)
        assert np.allclose(a, b, rtol=1e-11, atol=1e-12), field
    for name in ("drhs_dq", "drhs_dqd", "dmom_dq", "dmom_dqd", "dHw_dq"):
        a = _native_values(structured, structured.jac.native(name), values)
        b = _native_values(written, written.jac.native(name), values)
        assert np.allclose(a, b, rtol=1e-10, atol=1e-11), name


def test_energy_and_H_is_symmetric_positive(both_ways):
    structured, written = both_ways
    values = _state(structured, seed=5)
    H = _numeric(structured.H, values)
    assert np.allclose(H, H.T, rtol=0, atol=0)
    assert np.linalg.eigvalsh(H).min() > 0
    energies = [float(d.E.xreplace({s: values[s.name] for s in d.E.free_symbols})) for d in both_ways]
    assert energies[0] == pytest.approx(energies[1], rel=1e-12)


def test_v2pt_theory_on_every_point_gives_the_same_energies():
    plain, v2pt = chain(3), chain(3, v2pt=True)
    values = {}
    for model in (plain, v2pt):
        T, V = expand_intermediates(model.T), expand_intermediates(model.V)
        subs = {s: 0.3 + 0.1 * i for i, s in enumerate(sorted(T.free_symbols | V.free_symbols, key=str))
                if s.name != "g"}
        subs.update({s: 9.81 for s in (T.free_symbols | V.free_symbols) if s.name == "g"})
        values[model is plain] = (float(T.xreplace(subs)), float(V.xreplace(subs)))
    assert values[True] == pytest.approx(values[False], rel=1e-12)


def test_kinetic_energy_keeps_the_tree_small():
    """The energy of a 12-link chain is a short sum over Intermediates, not an expanded tree."""
    model = chain(12)
    assert all(isinstance(s, Intermediate) for s in model.intermediates)
    assert sp.count_ops(model.T) < 2000
    assert len(model.intermediates) < 400


def test_constraint_on_a_body_model():
    """Constraints are derived from their own expressions beside the graph."""
    dyn = derive(chain(2, constraint=True))
    assert dyn.m == 1 and dyn.ops.graph is not None
    assert sp.simplify(dyn.J - sp.Matrix([[1, -sp.Rational(1, 2)]])) == sp.zeros(1, 2)


@pytest.fixture(scope="module")
def chain_module(tmp_path_factory):
    """The generated module of a 3-link chain (rk4 only)."""
    from lagrange_gen.codegen import generate_model
    from lagrange_gen.run.loader import import_generated
    where = tmp_path_factory.mktemp("structured")
    path = where / "chain_model.py"
    path.write_text("import sys\nsys.path.insert(0, %r)\nfrom test_structured import chain\nmodel = chain(3)\n"
                    % str(Path(__file__).parent))
    return import_generated(generate_model(path, where / "gen", methods=["rk4"]).path)


def test_robot_kernels_invert_each_other(chain_module):
    """inverse_dynamics(forward_dynamics_torques(tau)) = tau; bias at rest = gravity (Python
    bodies of the kernels, no numba compile)."""
    mod = chain_module
    n = mod.N_COORDS
    rng = np.random.default_rng(1)
    q, v, tau = rng.uniform(-1, 1, (3, n))
    p = np.array(mod.DEFAULT_PARAMS, dtype=float)
    H, qdd, out, g, b = np.empty((n, n)), np.empty(n), np.empty(n), np.empty(n), np.empty(n)
    mod.dynamics.py_func(q, v, 0.0, p, H, qdd)
    qdd = np.linalg.solve(H, qdd + tau)
    mod.inverse_dynamics.py_func(q, v, qdd, 0.0, p, out)
    assert np.allclose(out, tau, rtol=1e-12, atol=1e-12)
    mod.gravity_forces.py_func(q, 0.0, p, g)
    mod.bias_forces.py_func(q, np.zeros(n), 0.0, p, b)
    assert np.allclose(b, g, rtol=1e-13, atol=1e-13)


def test_compile_all_knows_every_kernel_of_a_body_model(chain_module):
    """lagrange_gen's compile-everything-now (bench, warm-up) has call arguments for each kernel
    a module from bodies lists (failed before: inverse_dynamics was unknown to it)."""
    from lagrange_gen.run.loader import kernel_call_args
    assert set(chain_module.KERNELS) <= set(kernel_call_args(chain_module))


def test_forward_dynamics_jacobian_is_the_derivative_of_the_accelerations(chain_module):
    mod = chain_module
    n = mod.N_COORDS
    rng = np.random.default_rng(4)
    q, v = rng.uniform(-1, 1, (2, n))
    p = np.array(mod.DEFAULT_PARAMS, dtype=float)
    H, W, Jq, Jqd = (np.empty((n, n)) for _ in range(4))
    qdd = np.empty(n)
    assert mod.forward_dynamics_jacobian(q, v, 0.0, p, H, qdd, Jq, Jqd, W) == 0
    assert np.allclose(qdd, mod.accelerations(q, v), rtol=1e-13, atol=1e-13)
    eps = 1e-6
    dq = np.array([(mod.accelerations(q + eps * e, v) - mod.accelerations(q - eps * e, v)) / (2 * eps)
                   for e in np.eye(n)]).T
    dv = np.array([(mod.accelerations(q, v + eps * e) - mod.accelerations(q, v - eps * e)) / (2 * eps)
                   for e in np.eye(n)]).T
    assert np.allclose(Jq, dq, rtol=1e-6, atol=1e-7)
    assert np.allclose(Jqd, dv, rtol=1e-6, atol=1e-7)


def test_gravity_needs_a_fixed_point():
    q = me.dynamicsymbols("q")
    N = me.ReferenceFrame("N")
    A = N.orientnew("A", "Axis", (q, N.z))
    P = me.Point("P")                      # no velocity set anywhere
    G = P.locatenew("G", A.x)
    body = me.Particle("m", G, 1.0)
    with pytest.raises(ModelError, match="fixed point"):
        lg.gravity_potential(N, -9.81 * N.z, body)
    with pytest.raises(ModelError, match="velocity"):
        lg.kinetic_energy(N, body)


def test_generated_text_does_not_depend_on_hash_order(tmp_path):
    """Node numbers follow creation order, never a set's: two processes with different hash
    seeds write the same module for a model built from bodies."""
    import os
    import subprocess
    import sys
    code = ("import sys, hashlib; sys.path.insert(0, %r)\n"
            "from lagrange_gen.model.model_file import load_model\n"
            "from lagrange_gen.codegen.generate import generate_parts\n"
            "m = load_model(%r, n=3)\n"
            "print(hashlib.sha1(generate_parts(m, %r, methods=['rk4']).text.encode()).hexdigest())\n"
            % (str(Path(__file__).parent), str(Path(__file__).parents[2] / "models" / "spatial_chain.py"),
               str(tmp_path)))
    digests = {subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                              env={**os.environ, "PYTHONHASHSEED": seed}).stdout.strip()
               for seed in ("1", "2")}
    assert len(digests) == 1
