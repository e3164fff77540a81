"""Linear oscillator m x'' = -k x (constant H, velocity-free forces: verlet runs explicitly).
k has no default, so a missing value must be reported by name."""
from lagrange_gen import Model, coordinates, parameters

x = coordinates("x")
m = parameters("m", defaults=(1.0,))
k = parameters("k")

model = Model("oscillator", coords=[x], T=m * x.d**2 / 2, V=k * x**2 / 2,
              description="Linear oscillator, omega = sqrt(k/m).")
