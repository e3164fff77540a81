"""A particle in V = c sqrt(x): the energy is finite at x = 0 but the force -c / (2 sqrt(x)) and
its Jacobian divide by zero there, so an implicit step from x = 0 meets an infinite Newton
matrix, which must be reported as a non-finite value (BlowUp), not as a singular matrix."""
import sympy as sp

from lagrange_gen import Model, coordinates, parameters

x = coordinates("x")
m, c = parameters("m c", defaults=(1.0, 1.0))

model = Model("sqrt_potential", coords=[x], T=m * x.d**2 / 2, V=c * sp.sqrt(x),
              description="Particle in V = c sqrt(x) (force singular at x = 0).")
