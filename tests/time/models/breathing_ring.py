"""Test model: breathing_frame.py's particle held on the unit circle x^2 + y^2 = 1 of the
turning, breathing frame (a bead on a ring): H(t), gyroscopic T1, T0 and V(q, t) with a
constraint, for the constrained methods."""
import sympy as sp

from lagrange_gen import Model, coordinates, parameters, t

x, y, phi, s = coordinates("x y phi s")
m, k, F, w, nu, e = parameters("m k F w nu e", defaults=(1.0, 4.0, 0.5, 1.5, 2.0, 0.3))

X = s * (sp.cos(phi) * x - sp.sin(phi) * y)
Y = s * (sp.sin(phi) * x + sp.cos(phi) * y)
rate = lambda c: sum(sp.diff(c, v) * v.d for v in (x, y, phi, s))   # noqa: E731
T = m * (rate(X) ** 2 + rate(Y) ** 2) / 2
V = k * (x**2 + 2 * y**2) / 2 + F * sp.cos(nu * t) * x

model = Model("breathing_ring", coords=[x, y], T=T, V=V, constraints=[x**2 + y**2 - 1],
              prescribed={phi: w * t + e * sp.sin(nu * t), s: 1 + e * sp.sin(nu * t) / 2},
              description="Bead on a ring in a turning, breathing frame.")
