"""Planar pendulum in Cartesian coordinates (x, y) of the bob, with the length constraint
x^2 + y^2 - l^2 = 0 (an index-3 DAE when integrated; see the constrained steppers)."""
from lagrange_gen import Model, coordinates, parameters

x, y = coordinates("x y")
m, l, g = parameters("m l g", defaults=(1.0, 1.0, 9.81))

T = m * (x.d**2 + y.d**2) / 2
V = m * g * y
Phi = [(x**2 + y**2 - l**2) / 2]

model = Model("cartesian_pendulum", coords=[x, y], T=T, V=V, constraints=Phi,
              description="Planar pendulum in Cartesian coordinates with a length constraint.")
