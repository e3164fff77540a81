"""Bad input for the tests: the Cartesian pendulum with its length constraint stated twice (the
second a multiple of the first), so J has rank 1 < 2 everywhere."""
from lagrange_gen import Model, coordinates, parameters

x, y = coordinates("x y")
m, l, g = parameters("m l g", defaults=(1.0, 1.0, 9.81))

model = Model("redundant_pendulum", coords=[x, y], T=m * (x.d**2 + y.d**2) / 2, V=m * g * y,
              constraints=[x**2 + y**2 - l**2, 2 * x**2 + 2 * y**2 - 2 * l**2])
