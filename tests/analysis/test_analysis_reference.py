"""References of lagrange_gen.analysis: each must agree with an independent computation (a
second solver, a closed form, a second formulation, finite differences, sympy.mechanics)."""

import math

import numpy as np
import pytest

from lg_test_support import MODELS_DIR
from lagrange_gen.analysis import reference
from lagrange_gen.analysis.runs import params_of


def test_reference_agrees_with_second_solver_cart_pendulum(generated):
    mod = generated("cart_pendulum")
    p = params_of(mod)
    t = np.linspace(0.0, 10.0, 51)
    ref = reference.ode_reference(mod, p, np.array([0.1, 0.5]), np.zeros(2), 10.0, t,
                                  second="LSODA")
    assert ref.agreement < 1e-9
    assert np.allclose(ref.y_at(10.0), ref.y_end, atol=1e-10)


def test_reference_matches_closed_form_damped_oscillator(generated):
    """DOP853 at 1e-13 on the generated right-hand side against the closed-form solution."""
    mod = generated("damped_oscillator")
    c, b = 1e-2, 0.3
    p = params_of(mod, m=1.0, c=c, b=b)
    t = np.linspace(0.0, 5.0, 41)
    ref = reference.ode_reference(mod, p, np.array([1.0]), np.zeros(1), 5.0, t, second="LSODA")
    x, v = reference.oscillator_exact(t, 1.0, c, b)
    y = ref.y_at(t)
    assert np.max(np.abs(y[0] - x)) < 1e-10 and np.max(np.abs(y[1] - v)) < 1e-9


def test_cartesian_pendulum_reference_two_formulations_agree(generated):
    """Angle form vs index-1 Cartesian form; and the angle form stays on |x| = l."""
    mod = generated("cartesian_pendulum")
    p = params_of(mod)
    t = np.linspace(0.0, 10.0, 101)
    q0 = np.array([math.sin(0.5), -math.cos(0.5)])
    ref = reference.pendulum_angle_reference(mod, p, q0, np.zeros(2), 10.0, t)
    assert ref.agreement < 1e-8
    phi = reference.constraint_residual(mod, p, ref.y_at(t)[:2].T)
    assert phi.max() < 1e-12


def test_ode_jacobian_matches_finite_differences(generated):
    mod = generated("cart_pendulum")
    p = params_of(mod)
    f, jac = reference.ode_rhs(mod, p), reference.ode_jacobian(mod, p)
    y = np.array([0.3, -0.7, 0.5, 1.1])
    eps = 1e-6
    fd = np.column_stack([(f(0.0, y + eps * e) - f(0.0, y - eps * e)) / (2 * eps)
                          for e in np.eye(4)])
    np.testing.assert_allclose(jac(0.0, y), fd, atol=1e-7)


def test_sympy_mechanics_equations_are_the_same_system(generated):
    mod = generated("double_pendulum")
    p = params_of(mod)
    fm = reference.mechanics_rhs(MODELS_DIR / "double_pendulum.py", mod.PARAMS, p)
    f = reference.ode_rhs(mod, p)
    for y in np.random.default_rng(1).normal(size=(5, 4)):
        np.testing.assert_allclose(fm(0.0, y), f(0.0, y), rtol=1e-12, atol=1e-12)


def test_mechanics_refuses_dissipative_model():
    with pytest.raises(ValueError, match="conservative"):
        reference.mechanics_equations(MODELS_DIR / "damped_oscillator.py")
