"""Planar double pendulum in Cartesian coordinates of the two bobs, with two length constraints
(the same motion as models/double_pendulum.py in angles)."""
from lagrange_gen import Model, coordinates, parameters

x1, y1, x2, y2 = coordinates("x1 y1 x2 y2")
m1, m2, l1, l2, g = parameters("m1 m2 l1 l2 g", defaults=(1.0, 1.0, 1.0, 1.0, 9.81))

T = m1 * (x1.d**2 + y1.d**2) / 2 + m2 * (x2.d**2 + y2.d**2) / 2
V = g * (m1 * y1 + m2 * y2)
Phi = [(x1**2 + y1**2 - l1**2) / 2,
       ((x2 - x1)**2 + (y2 - y1)**2 - l2**2) / 2]

model = Model("cartesian_double_pendulum", coords=[x1, y1, x2, y2], T=T, V=V, constraints=Phi,
              description="Planar double pendulum in Cartesian coordinates, two length constraints.")
