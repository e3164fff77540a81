"""Damped, driven oscillator m x'' + c x' + k x = F0 sin(w t): nonconservative forces that
depend on the velocity (Rayleigh dissipation) and on time."""
import sympy as sp

from lagrange_gen import Model, coordinates, parameters, t

x = coordinates("x")
m, k, c, F0, w = parameters("m k c F0 w", defaults=(1.0, 4.0, 0.3, 1.0, 1.7))

model = Model("driven_oscillator", coords=[x], T=m * x.d**2 / 2, V=k * x**2 / 2,
              dissipation=c * x.d**2 / 2, forces={x: F0 * sp.sin(w * t)},
              description="Damped driven oscillator.")
