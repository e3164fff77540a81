"""Several friction elements (projected Gauss-Seidel) and a nonlinear strain (curvature term)."""

import textwrap

import numpy as np
import pytest

from lagrange_gen.codegen import generate_model
from lagrange_gen.run.loader import import_generated
from lagrange_gen.run.simulate import simulate

TWO_BLOCKS = """
from lagrange_gen import DryFriction, Model, coordinates, parameters
x1, x2 = coordinates("x1 x2")
m, k, F1, F2 = parameters("m k F1 F2", defaults=(1.0, 1.0, 0.1, 0.15))
model = Model("two_blocks", coords=[x1, x2], T=m * (x1.d**2 + x2.d**2) / 2, V=k * (x2 - x1)**2 / 2,
              elements=[DryFriction(x1, F1, name="f1"), DryFriction(x2, F2, name="f2")])
"""

HINGE = """
import sympy as sp
from lagrange_gen import Model, SaintVenant, coordinates, parameters, t
th = coordinates("th")
m, l, g, k, eta, a = parameters("m l g k eta a", defaults=(1.0, 1.0, 9.81, 50.0, 0.05, 8.0))
model = Model("plastic_pendulum", coords=[th], T=m * l**2 * th.d**2 / 2, V=-m * g * l * sp.cos(th),
              forces=[a * sp.sin(2 * t)],
              elements=[SaintVenant(strain=l * sp.sin(th), stiffness=k, threshold=eta, name="hinge")])
"""


def _module(tmp_path, source, name):
    path = tmp_path / f"{name}.py"
    path.write_text(textwrap.dedent(source))
    return import_generated(generate_model(path, tmp_path / "gen").path)


def test_blocks_stick_exactly_below_the_friction_bounds(tmp_path):
    mod = _module(tmp_path, TWO_BLOCKS, "two_blocks")
    traj = simulate(mod, method="implicit_euler", q0=[0.0, 0.08], t_end=5.0, h=1e-3)
    # Stick to round-off (PGS stops at its tolerance): no creep as with a regularized law.
    assert np.abs(traj.q - traj.q[0]).max() < 1e-14 and np.abs(traj.v).max() < 1e-15
    np.testing.assert_allclose(traj.element_state[-1], [-0.08, 0.08], atol=1e-12)  # balances the spring


def test_blocks_slide_dissipate_and_come_to_rest_within_the_bounds(tmp_path):
    mod = _module(tmp_path, TWO_BLOCKS, "two_blocks")
    traj = simulate(mod, method="implicit_euler", q0=[0.0, 1.0], t_end=20.0, h=1e-3)
    assert np.all(np.diff(traj.energy) <= 1e-12)             # friction only removes energy
    assert traj.energy[-1] < traj.energy[0] - 0.1
    spring = traj.q[-1, 1] - traj.q[-1, 0]
    assert np.abs(traj.v[-1000:]).max() < 1e-15 and abs(spring) <= 0.1 + 1e-12
    np.testing.assert_allclose(traj.element_state[-1], [-spring, spring], atol=1e-12)


def test_nonlinear_strain_discrete_residual(tmp_path):
    """H (v+ - v)/h - rhs(q+, v+, t+) + k u+ ds/dq(q+) = 0 at every step, with the return map
    on s = l sin(theta) (the Newton tangent includes the curvature term k u d2s/dq2)."""
    mod = _module(tmp_path, HINGE, "plastic_pendulum")
    h = 1e-3
    traj = simulate(mod, method="implicit_euler", q0=[0.3], t_end=10.0, h=h)
    p = np.array(list(traj.params.values()))
    k, eta = traj.params["k"], traj.params["eta"]
    H, rhs = np.empty((1, 1)), np.empty(1)
    s, G, coef = np.empty(1), np.empty((1, 1)), np.empty((1, 3))
    worst = 0.0
    for i in range(1, len(traj.t)):
        mod.dynamics(traj.q[i], traj.v[i], traj.t[i], p, H, rhs)
        mod.elements(traj.q[i], p, s, G, coef)
        res = H[0, 0] * (traj.v[i, 0] - traj.v[i - 1, 0]) / h - rhs[0] + k * traj.element_state[i, 0] * G[0, 0]
        worst = max(worst, abs(res))
    assert worst < 1e-8
    u = traj.element_state[:, 0]
    assert np.sum(np.abs(np.abs(u) - eta) < 1e-12) > 100     # the hinge did yield
    assert traj.newton_iters[1:].max() <= 8
