"""Simple pendulum theta'' = -(g/l) sin(theta) (HARD_CASES case 6 with g = l = m = 1)."""
import sympy as sp

from lagrange_gen import Model, coordinates, parameters

th = coordinates("theta")
m, l, g = parameters("m l g", defaults=(1.0, 1.0, 1.0))

model = Model("pendulum", coords=[th], T=m * l**2 * th.d**2 / 2, V=-m * g * l * sp.cos(th),
              description="Simple pendulum.")
