"""The Jacobian kernels against plain sympy differentiation of the printed quantities.

derive assembles the velocity Jacobians from dH/dq (d rhs/dqd = dQ/dqd - (D + Hdot - D^T)) and
d(H w)/dq, d(J w)/dq, d(J^T lam)/dq from first and second derivatives it already has; here each
is recomputed the obvious way (sympy Matrix.jacobian of rhs, momentum_rate, H w, J w, J^T lam)
and compared at random states through the printed source.
"""

import numpy as np
import pytest
import sympy as sp

from lg_test_support import MODELS_DIR
from lagrange_gen import load_model
from lagrange_gen.codegen import generate_text
from lagrange_gen.derive import derive
from lagrange_gen.run.loader import import_generated


def _direct(dyn):
    """{kernel output: lambdified direct Jacobian} over (q, qd, t, p, w, lam)."""
    q, qd, w, lam = dyn.q, dyn.qd, sp.Matrix(dyn.aux["w"]), sp.Matrix(dyn.aux["lam"])
    args = [q, qd, dyn.t, dyn.params, list(w), list(lam)]
    exprs = {"drhs_dq": dyn.rhs.jacobian(q), "drhs_dqd": dyn.rhs.jacobian(qd),
             "dmom_dq": dyn.momentum_rate.jacobian(q), "dmom_dqd": dyn.momentum_rate.jacobian(qd),
             "dHw_dq": (dyn.H * w).jacobian(q)}
    if dyn.m:
        exprs["dJw_dq"] = (dyn.J * w).jacobian(q)
        exprs["dJTlam_dq"] = (dyn.J.T * lam).jacobian(q)
    return {k: sp.lambdify(args, v) for k, v in exprs.items()}


@pytest.mark.parametrize("stem", ["double_pendulum", "spring_mass_chain", "cart_pendulum",
                                  "spherical_pendulum", "cartesian_pendulum"])
def test_jacobian_kernels_equal_direct_differentiation(tmp_path, stem):
    model = load_model(MODELS_DIR / f"{stem}.py")
    text, _, target = generate_text(model, tmp_path, methods=[])
    target.write_text(text)
    mod, dyn = import_generated(target), derive(model)
    direct = _direct(dyn)
    n, m = dyn.n, dyn.m
    rng = np.random.default_rng(11)
    p = np.array([1.0 if d is None else d for d in model.defaults()])
    A, B = np.empty((n, n)), np.empty((n, n))
    for _ in range(4):
        q, qd, w = rng.uniform(-1, 1, n) + 0.4, rng.uniform(-1, 1, n), rng.uniform(-1, 1, n)
        lam, t = rng.uniform(-1, 1, m), rng.uniform(0, 2)
        values = (q, qd, t, p, w, lam)

        def check(name, got):
            want = np.array(direct[name](*values), dtype=float).reshape(got.shape)
            np.testing.assert_allclose(got, want, rtol=1e-11, atol=1e-11 * (1 + np.abs(want).max()))
        mod.rhs_jacobian.py_func(q, qd, t, p, A, B)
        check("drhs_dq", A), check("drhs_dqd", B)
        mod.momentum_rate_jacobian.py_func(q, qd, t, p, A, B)
        check("dmom_dq", A), check("dmom_dqd", B)
        mod.mass_matvec_dq.py_func(q, w, t, p, A)
        check("dHw_dq", A)
        if m:
            dJw = np.empty((m, n))
            mod.constraint_dq.py_func(q, w, lam, t, p, dJw, A)
            check("dJw_dq", dJw), check("dJTlam_dq", A)
