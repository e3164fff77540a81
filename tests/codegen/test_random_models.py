"""Property test: for random scleronomic T = 1/2 qd^T A(q) qd with random SPD A(q), the printed
kernels agree with sympy.lambdify of the symbolic results (derive and print checked separately)."""

import itertools

import numpy as np
import sympy as sp
from hypothesis import given, settings, strategies as st

from lagrange_gen import Model, coordinates, parameters
from lagrange_gen.codegen import generate_text, make_kernels
from lagrange_gen.derive import derive
from lagrange_gen.loader import import_generated

_counter = itertools.count()
small_ints = st.integers(min_value=-3, max_value=3)


@st.composite
def random_models(draw):
    n = draw(st.integers(min_value=1, max_value=3))
    q = coordinates(" ".join(f"r{i}" for i in range(n)))
    q = q if isinstance(q, list) else [q]
    a, b = parameters("a b", defaults=(draw(st.floats(0.5, 2.0)), draw(st.floats(0.5, 2.0))))
    # B(q) with trigonometric and polynomial entries; A = B B^T + a I is SPD for any q.
    B = sp.Matrix(n, n, lambda i, j: draw(small_ints) + draw(small_ints) * sp.cos(q[j])
                  + draw(small_ints) * sp.sin(q[i]) * b + draw(small_ints) * q[(i + j) % n] ** 2 / 4)
    A = B * B.T + a * sp.eye(n)
    qd = sp.Matrix([c.d for c in q])
    T = (qd.T * A * qd)[0, 0] / 2
    V = sum(draw(small_ints) * sp.cos(c) + b * c**2 for c in q)
    D = sum(draw(st.integers(0, 2)) * c.d**2 / 2 for c in q)
    return Model(f"random_{next(_counter)}", coords=q, T=T, V=V, dissipation=D)


@settings(max_examples=12, deadline=None)
@given(model=random_models(), seed=st.integers(0, 2**16))
def test_printed_kernels_equal_lambdified_symbolics(tmp_path_factory, model, seed):
    out = tmp_path_factory.mktemp("rand")
    model.source_path = str(out / "model.py")
    text, _, target = generate_text(model, out, methods=[])
    target.write_text(text)
    mod = import_generated(target)
    dyn = derive(model)
    n = dyn.n
    args = [dyn.q, dyn.qd, dyn.t, dyn.params]
    f_H = sp.lambdify(args, dyn.H)
    f_rhs = sp.lambdify(args, dyn.rhs)
    f_E = sp.lambdify(args, dyn.E)
    f_jac = {k: sp.lambdify(args + [dyn.aux["w"]], dyn.jac[k]) for k in ("drhs_dq", "drhs_dqd", "dHw_dq", "dmom_dq")}
    rng = np.random.default_rng(seed)
    p = np.array(model.defaults())
    H, rhs = np.empty((n, n)), np.empty(n)
    Jq, Jqd, Hw = np.empty((n, n)), np.empty((n, n)), np.empty((n, n))
    for _ in range(5):
        q, qd, w = rng.uniform(-2, 2, n), rng.uniform(-2, 2, n), rng.uniform(-2, 2, n)
        # py_func runs the printed source without numba; the compiled path is covered elsewhere.
        mod.dynamics.py_func(q, qd, 0.0, p, H, rhs)
        np.testing.assert_allclose(H, f_H(q, qd, 0.0, p), rtol=1e-11, atol=1e-11)
        np.testing.assert_allclose(rhs, np.ravel(f_rhs(q, qd, 0.0, p)), rtol=1e-11, atol=1e-10)
        np.testing.assert_allclose(mod.energy.py_func(q, qd, 0.0, p), f_E(q, qd, 0.0, p), rtol=1e-11, atol=1e-11)
        mod.rhs_jacobian.py_func(q, qd, 0.0, p, Jq, Jqd)
        np.testing.assert_allclose(Jq, f_jac["drhs_dq"](q, qd, 0.0, p, w), rtol=1e-10, atol=1e-10)
        np.testing.assert_allclose(Jqd, f_jac["drhs_dqd"](q, qd, 0.0, p, w), rtol=1e-10, atol=1e-10)
        mod.mass_matvec_dq.py_func(q, w, p, Hw)
        np.testing.assert_allclose(Hw, f_jac["dHw_dq"](q, qd, 0.0, p, w), rtol=1e-10, atol=1e-10)
        mod.momentum_rate_jacobian.py_func(q, qd, 0.0, p, Jq, Jqd)
        np.testing.assert_allclose(Jq, f_jac["dmom_dq"](q, qd, 0.0, p, w), rtol=1e-10, atol=1e-10)
    # and the jacobian really is the derivative of rhs: a finite-difference cross-check
    q, qd = rng.uniform(-2, 2, n), rng.uniform(-2, 2, n)
    mod.rhs_jacobian.py_func(q, qd, 0.0, p, Jq, Jqd)
    eps = 1e-6
    for i in range(n):
        dq = np.zeros(n)
        dq[i] = eps
        r1, r2 = np.empty(n), np.empty(n)
        mod.dynamics.py_func(q + dq, qd, 0.0, p, H, r1)
        mod.dynamics.py_func(q - dq, qd, 0.0, p, H, r2)
        np.testing.assert_allclose((r1 - r2) / (2 * eps), Jq[:, i], rtol=1e-5, atol=1e-5)
    assert [k.name for k in make_kernels(dyn)][:2] == ["mass_matrix", "dynamics"]
