"""Test model: a particle in a plane turning at the constant rate w, seen from the turning
frame (x, y): T = m ((x' - w y)^2 + (y' + w x)^2) / 2 has a gyroscopic T1 = m w (x y' - y x')
and T0 = m w^2 (x^2 + y^2) / 2; V = k (x^2 + 2 y^2) / 2 + b x^4 / 4 is anharmonic. L has no
explicit t, so the Jacobi integral E = T2 - T0 + V is conserved."""
from lagrange_gen import Model, coordinates, parameters

x, y = coordinates("x y")
m, k, b, w = parameters("m k b w", defaults=(1.0, 4.0, 2.0, 0.7))

model = Model("rotating_anharmonic", coords=[x, y],
              T=m * ((x.d - w * y) ** 2 + (y.d + w * x) ** 2) / 2,
              V=k * (x**2 + 2 * y**2) / 2 + b * x**4 / 4,
              description="Particle in a uniformly turning plane, anharmonic potential.")
