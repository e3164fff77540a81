"""A mass m in the central field -k m / |x| in Cartesian coordinates (x, y): the Kepler problem
without a coordinate singularity but with a square root in every force."""
import sympy as sp

from lagrange_gen import Model, coordinates, parameters

x, y = coordinates("x y")
m, k = parameters("m k", defaults=(1.0, 1.0))

T = m * (x.d**2 + y.d**2) / 2
V = -k * m / sp.sqrt(x**2 + y**2)

model = Model("central_field", coords=[x, y], T=T, V=V,
              description="Particle in the central field -k m / r, Cartesian coordinates.")
