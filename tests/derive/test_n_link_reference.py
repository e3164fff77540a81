"""The n-link pendulum's printed kernels against an independent derivation: sympy.physics.mechanics
LagrangesMethod (frames, points, particles; nothing shared with lagrange_gen.derive), lambdified.

LagrangesMethod gives M(q) qdd = F(q, qd); ours H(q) qdd = rhs(q, qd). Both sides are the same
equations written the same way (Lagrange's equations of the same L), so M = H and F = rhs
entry by entry, not only up to a factor.
"""

import sys

import numpy as np
import pytest
import sympy as sp
from sympy.physics import mechanics as me

from lg_test_support import MODELS_DIR
from lagrange_gen.codegen import generate_text
from lagrange_gen.run.loader import import_generated

sys.path.insert(0, str(MODELS_DIR))
from n_link_pendulum import n_link_pendulum  # noqa: E402


def lagranges_method_chain(n):
    """(M(q, params), F(q, qd, params)) lambdified, params = (m, l, g): point masses m on
    massless rods l, absolute angles from the downward vertical, gravity g along -N.y."""
    q = me.dynamicsymbols(f"q1:{n + 1}")
    m, l, g = sp.symbols("m l g")
    N, O = me.ReferenceFrame("N"), me.Point("O")
    O.set_vel(N, 0)
    prev, particles = O, []
    for i in range(n):
        frame = N.orientnew(f"A{i}", "Axis", [q[i], N.z])
        point = prev.locatenew(f"P{i}", -l * frame.y)
        point.v2pt_theory(prev, N, frame)
        particle = me.Particle(f"Pa{i}", point, m)
        particle.potential_energy = m * g * point.pos_from(O).dot(N.y)
        particles.append(particle)
        prev = point
    lm = me.LagrangesMethod(me.Lagrangian(N, *particles), q)
    lm.form_lagranges_equations()
    qs, vs = sp.symbols(f"a0:{n}"), sp.symbols(f"v0:{n}")
    plain = {qi.diff(): v for qi, v in zip(q, vs)}
    M = lm.mass_matrix.xreplace(plain).xreplace(dict(zip(q, qs)))
    F = lm.forcing.xreplace(plain).xreplace(dict(zip(q, qs)))
    return sp.lambdify([qs, (m, l, g)], M), sp.lambdify([qs, vs, (m, l, g)], F)


@pytest.mark.parametrize("n", [1, 2, 3, 4, 5, 6])
def test_kernels_match_lagranges_method(tmp_path, n):
    model = n_link_pendulum(n)
    model.source_path = str(tmp_path / "model.py")
    text, _, target = generate_text(model, tmp_path, methods=["explicit_euler"])
    target.write_text(text)
    mod = import_generated(target)
    f_M, f_F = lagranges_method_chain(n)
    rng = np.random.default_rng(100 + n)
    H, rhs = np.empty((n, n)), np.empty(n)
    for _ in range(6):
        q, qd = rng.uniform(-np.pi, np.pi, n), rng.uniform(-2, 2, n)
        params = rng.uniform(0.5, 2.0, 3)                   # m, l, g: not the defaults
        p = np.array([dict(zip(("m", "l", "g"), params))[k] for k in mod.PARAMS])
        # py_func runs the printed source without numba (the compiled path is covered elsewhere)
        mod.dynamics.py_func(q, qd, 0.0, p, H, rhs)
        M = np.array(f_M(q, params), dtype=float)
        F = np.array(f_F(q, qd, params), dtype=float).ravel()
        np.testing.assert_allclose(H, M, rtol=1e-12, atol=1e-12 * np.abs(M).max())
        np.testing.assert_allclose(rhs, F, rtol=1e-11, atol=1e-11 * (1 + np.abs(F).max()))
