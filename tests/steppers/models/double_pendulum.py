"""Planar double pendulum in absolute angles (H depends on q: verlet needs Newton)."""
import sympy as sp

from lagrange_gen import Model, coordinates, parameters

a, b = coordinates("a b")
m1, m2, l1, l2, g = parameters("m1 m2 l1 l2 g", defaults=(1.0, 1.0, 1.0, 1.0, 9.81))

T = (m1 + m2) * l1**2 * a.d**2 / 2 + m2 * l2**2 * b.d**2 / 2 \
    + m2 * l1 * l2 * a.d * b.d * sp.cos(a - b)
V = -(m1 + m2) * g * l1 * sp.cos(a) - m2 * g * l2 * sp.cos(b)

model = Model("double_pendulum_test", coords=[a, b], T=T, V=V,
              description="Double pendulum (stepper tests).")
