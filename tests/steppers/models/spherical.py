"""Spherical pendulum in polar/azimuth angles: H = diag(m l^2, m l^2 sin(q1)^2) is singular at
q1 = 0 (a coordinate singularity that must give SingularMass, not NaN)."""
import sympy as sp

from lagrange_gen import Model, coordinates, parameters

q1, q2 = coordinates("q1 q2")
m, l, g = parameters("m l g", defaults=(1.0, 1.0, 9.81))

T = m * l**2 * (q1.d**2 + sp.sin(q1)**2 * q2.d**2) / 2
V = m * g * l * sp.cos(q1)

model = Model("spherical_test", coords=[q1, q2], T=T, V=V, description="Spherical pendulum.")
