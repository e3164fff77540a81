"""Planar pendulum in Cartesian coordinates with the length constraint, released from rest at
x = -l sin(theta0): the bob passes the vertical x = 0 after a quarter period K(sin(theta0 / 2))
/ omega, omega = sqrt(g / l) (complete elliptic integral K)."""

from lagrange_gen import Model, coordinates, parameters

x, y = coordinates("x y")
m, l, g = parameters("m l g", defaults=(1.0, 1.0, 9.81))

model = Model("cartesian_pendulum_events", coords=[x, y], T=m * (x.d**2 + y.d**2) / 2,
              V=m * g * y, constraints=[(x**2 + y**2 - l**2) / 2], events={"vertical": x})
