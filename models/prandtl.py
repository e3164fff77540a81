"""Prandtl model (Lamarque's lecture, HARD_CASES case 9): m x'' + k0 x + k1 u = F(t) with one
Saint-Venant element (stiffness k1, threshold eta) on x, F = f cos(omega t). With k0 = 0 the
response drifts to large amplitude (about 2 f / (m omega^2) = 400); with k0 = 1 (linear
hardening, see prandtl_hardening.py) it stays near f / (m (omega0^2 - omega^2))."""
import sympy as sp

from lagrange_gen import Model, SaintVenant, coordinates, parameters, t

x = coordinates("x")
m, k0, k1, eta, f, omega = parameters("m k0 k1 eta f omega", defaults=(1.0, 0.0, 1.0, 1.0, 2.0, 0.1))

model = Model("prandtl", coords=[x], T=m * x.d**2 / 2, V=k0 * x**2 / 2,
              forces=[f * sp.cos(omega * t)],
              elements=[SaintVenant(strain=x, stiffness=k1, threshold=eta, name="slider")],
              description="Prandtl model: mass, Saint-Venant element, harmonic force.")
