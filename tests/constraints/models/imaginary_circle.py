"""Bad input for the tests: x^2 + y^2 + l^2 = 0 has no real solution (J = 2 (x, y) has full rank
away from the origin, so only the projection can tell)."""
from lagrange_gen import Model, coordinates, parameters

x, y = coordinates("x y")
m, l, g = parameters("m l g", defaults=(1.0, 1.0, 9.81))

model = Model("imaginary_circle", coords=[x, y], T=m * (x.d**2 + y.d**2) / 2, V=m * g * y,
              constraints=[x**2 + y**2 + l**2])
