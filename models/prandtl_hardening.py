"""Prandtl model with linear hardening: a parallel spring k0 = 1 beside the Saint-Venant element
(HARD_CASES case 9, second variant)."""
import sympy as sp

from lagrange_gen import Model, SaintVenant, coordinates, parameters, t

x = coordinates("x")
m, k0, k1, eta, f, omega = parameters("m k0 k1 eta f omega", defaults=(1.0, 1.0, 1.0, 1.0, 2.0, 0.1))

model = Model("prandtl_hardening", coords=[x], T=m * x.d**2 / 2, V=k0 * x**2 / 2,
              forces=[f * sp.cos(omega * t)],
              elements=[SaintVenant(strain=x, stiffness=k1, threshold=eta, name="slider")],
              description="Prandtl model with linear hardening (parallel spring k0).")
