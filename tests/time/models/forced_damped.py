"""Test model: a pendulum on a sprung cart, damped on both coordinates and forced on the cart by
F cos(nu t) (from the issue: the energy balance E - E0 - W on a damped, forced system)."""
import sympy as sp

from lagrange_gen import Model, coordinates, parameters, t

x, th = coordinates("x theta")
M, m, l, k, g, c, d, F, nu = parameters("M m l k g c d F nu",
                                        defaults=(1.0, 0.5, 1.0, 10.0, 9.81, 0.3, 0.1, 2.0, 3.0))
T = (M + m) * x.d**2 / 2 + m * l * x.d * th.d * sp.cos(th) + m * l**2 * th.d**2 / 2
V = k * x**2 / 2 - m * g * l * sp.cos(th)
model = Model("forced_damped", coords=[x, th], T=T, V=V, forces={x: F * sp.cos(nu * t)},
              dissipation=c * x.d**2 / 2 + d * th.d**2 / 2,
              description="Damped, forced pendulum on a sprung cart.")
