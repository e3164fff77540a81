"""Test model: a mass on a spring pushed by the input u. H is constant and the forces are
velocity-free, so verlet runs its explicit path, which caches the acceleration between steps."""
from lagrange_gen import Model, coordinates, inputs, parameters

x = coordinates("x")
m, k = parameters("m k", defaults=(1.0, 4.0))
u = inputs("u")

model = Model("forced_oscillator", coords=[x], T=m * x.d**2 / 2, V=k * x**2 / 2, forces={x: u},
              inputs=[u])
