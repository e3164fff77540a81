"""Damped linear oscillator written with a compliance: m x'' + b x' + x / c = 0 (HARD_CASES
cases 3 and 4). omega = 1 / sqrt(m c); a small compliance c is a stiff spring (Lacoursiere:
constraints are the limit c -> 0). With b = 0 it is the test equation of the tau = h omega
stability analysis."""
from lagrange_gen import Model, coordinates, parameters

x = coordinates("x")
m, c, b = parameters("m c b", defaults=(1.0, 1.0, 0.0))

model = Model("damped_oscillator", coords=[x], T=m * x.d**2 / 2, V=x**2 / (2 * c),
              dissipation=b * x.d**2 / 2,
              description="Damped oscillator m x'' + b x' + x / c = 0 (compliance c).")
