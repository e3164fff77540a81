"""Coulomb-damped oscillator: m x'' + k x + F_d Sign(x') ∋ 0. Free decay from x0 = 1.05 with
m = k = 1, F_d = 0.1: turning points 0.85, 0.65, 0.45, 0.25, 0.05 at t = j pi, rest at -0.05."""
from lagrange_gen import DryFriction, Model, coordinates, parameters

x = coordinates("x")
m, k, Fd = parameters("m k Fd", defaults=(1.0, 1.0, 0.1))

model = Model("coulomb_oscillator", coords=[x], T=m * x.d**2 / 2, V=k * x**2 / 2,
              elements=[DryFriction(rate_of=x, bound=Fd, name="friction")],
              description="Oscillator with Coulomb dry friction.")
