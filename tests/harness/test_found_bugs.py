"""Bugs the harness found, each as the smallest model that shows it (fails until fixed)."""

import sympy as sp

from lagrange_gen import coordinates, parameters

from .check import check_model
from .strategies import DrawnModel


def test_element_strain_with_abs_is_differentiated_exactly(tmp_path):
    """Found by the thorough profile (strain r0 + k0*Abs(r0)/r0**3): a strain using a function
    symengine cannot differentiate exactly (Abs; sign, Min, Piecewise likewise) made generation
    fail with PrintMethodNotImplementedError on Derivative(Abs(u), u). derive() picks the sympy
    backend for such a model, but derive/elements.py differentiates the strains with
    backend.jacobian's default backend (symengine), which leaves the derivative unevaluated."""
    u = coordinates("u")
    k, eta = parameters("k eta", defaults=(2.0, 0.5))
    drawn = DrawnModel(name="abs_strain", coords=[u], radial=[False], params=[k, eta],
                       T=u.d**2 / 2, V=u**2 / 2, elements=[("saint_venant", u * sp.Abs(u), k, eta, None)])
    assert not check_model(drawn, [], tmp_path, ("py_func",), seed=1, n_states=2)
