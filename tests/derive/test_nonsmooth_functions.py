"""Models using functions whose derivative symengine leaves unevaluated (Abs, sign) are derived
by sympy: the printed Jacobians are real derivatives, not Derivative(...) placeholders."""

import numpy as np
import sympy as sp

from lagrange_gen import Model, coordinates, parameters
from lagrange_gen.codegen import generate_text
from lagrange_gen.derive.backend import backend_for
from lagrange_gen.run.loader import import_generated


def test_quadratic_drag_with_abs_is_differentiated_exactly(tmp_path):
    x, th = coordinates("x th")
    c, k = parameters("c k", defaults=(0.3, 2.0))
    T = (x.d**2 + th.d**2 + x.d * th.d * sp.cos(th)) / 2
    D = c * (sp.Abs(x.d) ** 3 + sp.Abs(th.d) ** 3) / 3      # quadratic drag -c |v| v
    model = Model("drag", coords=[x, th], T=T, V=k * x**2 / 2 - sp.cos(th), dissipation=D)
    assert backend_for([D]) == "sympy" and backend_for([T]) in ("symengine", "sympy")
    model.source_path = str(tmp_path / "model.py")
    text, _, target = generate_text(model, tmp_path, methods=["implicit_euler"])
    assert "Derivative" not in text
    target.write_text(text)
    mod = import_generated(target)
    p, eps = np.array([0.3, 2.0]), 1e-6
    q, v = np.array([0.4, -0.7]), np.array([0.8, -1.3])       # away from the kinks at v = 0
    H, r0, r1, Jq, Jv = np.empty((2, 2)), np.empty(2), np.empty(2), np.empty((2, 2)), np.empty((2, 2))
    mod.rhs_jacobian.py_func(q, v, 0.0, p, Jq, Jv)
    for i in range(2):
        dv = np.eye(2)[i] * eps
        mod.dynamics.py_func(q, v + dv, 0.0, p, H, r1)
        mod.dynamics.py_func(q, v - dv, 0.0, p, H, r0)
        np.testing.assert_allclose(Jv[:, i], (r1 - r0) / (2 * eps), rtol=1e-6, atol=1e-8)
