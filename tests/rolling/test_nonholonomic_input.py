"""Nonholonomic input: the one-line ModelError of each bad velocity constraint, what derive
emits for a good one (A, b, gamma written out by hand), and which methods apply."""

import numpy as np
import pytest
import sympy as sp

from lagrange_gen import Model, ModelError, SimulationError, coordinates, parameters, t
from lagrange_gen.derive.dynamics import derive
from lagrange_gen.run.simulate import simulate
from lagrange_gen.steppers.core import registry


def _sleigh(constraint=None, **extra):
    x, y, th = coordinates("x y theta")
    a = parameters("a", defaults=(0.5,))
    c = constraint(x, y, th, a) if constraint else -sp.sin(th) * x.d + sp.cos(th) * y.d - a * th.d
    return Model("sleigh", coords=[x, y, th], T=(x.d**2 + y.d**2 + th.d**2) / 2,
                 nonholonomic=[c], **extra)


def test_a_good_constraint_gives_A_b_gamma():
    """A = dc/dqdot, b = c(qdot = 0), gamma = -(dc/dq qdot + dc/dt), from the sleigh's
    constraint -sin(th) x' + cos(th) y' - a th' written out by hand."""
    dyn = derive(_sleigh())
    x, y, th = dyn.q
    xd, yd, thd = dyn.qd
    a = dyn.params[0]
    assert dyn.n_nonholonomic == 1
    assert sp.simplify(dyn.nh_A - sp.Matrix([[-sp.sin(th), sp.cos(th), -a]])) == sp.zeros(1, 3)
    assert dyn.nh_b == sp.zeros(1, 1)
    expected = thd * (sp.cos(th) * xd + sp.sin(th) * yd)
    assert sp.simplify(dyn.nh_gamma[0] - expected) == 0


def test_an_equation_means_lhs_minus_rhs_and_time_goes_into_b_and_gamma():
    x = coordinates("x")
    model = Model("belt", coords=[x], T=x.d**2 / 2, nonholonomic=[sp.Eq(x.d, sp.cos(t))])
    dyn = derive(model)
    assert dyn.nh_A == sp.Matrix([[1]])
    assert sp.simplify(dyn.nh_b[0] + sp.cos(t)) == 0
    assert sp.simplify(dyn.nh_gamma[0] + sp.sin(t)) == 0      # A x'' = gamma = -db/dt


@pytest.mark.parametrize("constraint, message", [
    (lambda x, y, th, a: x.d**2 - y.d, r"not linear in the velocities: the term x_dot\*\*2"),
    (lambda x, y, th, a: sp.sin(th.d) + x.d, r"the term sin\(theta_dot\)"),
    (lambda x, y, th, a: x.d * y.d, r"the term x_dot\*y_dot"),
    (lambda x, y, th, a: x - a * th, r"has no velocity in it; a position constraint"),
])
def test_bad_constraint_is_one_line_naming_it(constraint, message):
    with pytest.raises(ModelError, match=message) as info:
        _sleigh(constraint)
    text = str(info.value)
    assert "\n" not in text and "model sleigh: nonholonomic constraint 0" in text


def test_together_with_holonomic_constraints_is_accepted_and_derived():
    """A sleigh held on the line y = x: Phi = x - y next to the knife edge (the bicycle has both
    kinds); J and A come out of derive unchanged by each other."""
    x, y, th = coordinates("x y theta")
    dyn = derive(_sleigh(constraints=[x - y]))
    assert dyn.J == sp.Matrix([[1, -1, 0]])
    assert sp.simplify(dyn.nh_A[:, :2] - sp.Matrix([[-sp.sin(th), sp.cos(th)]])) == sp.zeros(1, 2)
    assert [str(s) for s in dyn.nh_A[0, 2].free_symbols] == ["a"]


def test_together_with_elements_is_refused_in_one_line():
    from lagrange_gen import SaintVenant
    x, y, th = coordinates("x y theta")
    with pytest.raises(ModelError, match="nonholonomic constraints together with nonsmooth "
                                         "elements are not supported by any method yet"):
        _sleigh(elements=[SaintVenant(x, 1.0, threshold=0.1)])


def test_a_velocity_in_constraints_points_to_nonholonomic():
    x = coordinates("x")
    with pytest.raises(ModelError, match="velocity constraints .* go in nonholonomic="):
        Model("belt", coords=[x], T=x.d**2 / 2, constraints=[x.d - 1])


def test_only_the_nonholonomic_methods_apply():
    assert registry.applicable_methods(0, 0, 0, 1) == registry.NONHOLONOMIC_METHODS
    assert "nonholonomic_rk4" in registry.NONHOLONOMIC_METHODS
    assert not set(registry.NONHOLONOMIC_METHODS) & set(registry.applicable_methods(0, 0, 0, 0))
    assert "ignores the model's nonholonomic constraints" in registry.inapplicable("rk4", 0, 0, 0, 2)
    assert "has none" in registry.inapplicable("nonholonomic_rk4", 0, 0, 0, 0)
    assert "does not treat holonomic constraints" in registry.inapplicable("nonholonomic_rk4", 1, 0, 0, 1)
    assert registry.applicable_methods(1, 0, 0, 1) == ("nonholonomic_midpoint",)
    assert "not supported by any method" in registry.inapplicable("nonholonomic_midpoint", 0, 1, 0, 1)


def test_another_method_on_a_rolling_model_is_one_line(generated):
    module = generated("chaplygin_sleigh")
    with pytest.raises(SimulationError, match="method 'rk4' ignores the model's nonholonomic "
                                              "constraints \\(use nonholonomic_rk4, "
                                              "nonholonomic_midpoint\\)") as info:
        simulate(module, "rk4", [0, 0, 0], [1.0, 0, 0], t_end=0.1, h=0.01)
    assert "\n" not in str(info.value)


def test_inconsistent_v0_is_projected_with_a_warning(generated):
    """v0 = (0, 1, 0) on the sleigh (a = 0.5, m = 1, I = 0.2): the H-metric projection onto
    -sin(th) x' + cos(th) y' - a th' = 0 at th = 0 removes (H^-1 A^T) eta with
    A = (0, 1, -a), A H^-1 A^T = 1 + a^2 / I = 2.25, eta = -1 / 2.25: v = (0, 1 - 1/2.25,
    a / (I 2.25))."""
    module = generated("chaplygin_sleigh")
    with pytest.warns(UserWarning, match=r"v0 violates the nonholonomic constraints \(max\|A v0 "
                                         r"\+ b\| = 1\)"):
        traj = simulate(module, "nonholonomic_rk4", [0, 0, 0], [0, 1.0, 0], t_end=0.01, h=0.01)
    np.testing.assert_allclose(traj.v[0], [0.0, 1 - 1 / 2.25, 0.5 / (0.2 * 2.25)], rtol=1e-14)
    assert traj.saved["velocity_constraint_error"][0, 0] < 1e-15


def test_equilibrium_refuses_nonholonomic_models_in_one_line(generated):
    import lagrange_gen as lg
    module = generated("chaplygin_sleigh")
    with pytest.raises(SimulationError, match="nonholonomic constraints is not implemented yet"):
        lg.equilibrium(module, [0, 0, 0])
