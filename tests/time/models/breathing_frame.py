"""Test model: a particle seen from a frame that turns (angle phi(t)) and breathes (scale
s(t)). The inertial position is s(t) R(phi(t)) (x, y) with

    phi = w t + e sin(nu t),    s = 1 + e sin(nu t) / 2,

so T = T2 + T1 + T0 has H = m s(t)^2 I (time-dependent), gyroscopic T1 (Coriolis) and T0
(centrifugal), and V(q, t) = k (x^2 + 2 y^2) / 2 + F cos(nu t) x is time-dependent too."""
import sympy as sp

from lagrange_gen import Model, coordinates, parameters, t

x, y, phi, s = coordinates("x y phi s")
m, k, F, w, nu, e = parameters("m k F w nu e", defaults=(1.0, 4.0, 0.5, 1.5, 2.0, 0.3))

X = s * (sp.cos(phi) * x - sp.sin(phi) * y)
Y = s * (sp.sin(phi) * x + sp.cos(phi) * y)
rate = lambda c: sum(sp.diff(c, v) * v.d for v in (x, y, phi, s))   # noqa: E731
T = m * (rate(X) ** 2 + rate(Y) ** 2) / 2
V = k * (x**2 + 2 * y**2) / 2 + F * sp.cos(nu * t) * x

model = Model("breathing_frame", coords=[x, y], T=T, V=V,
              prescribed={phi: w * t + e * sp.sin(nu * t), s: 1 + e * sp.sin(nu * t) / 2},
              description="Particle in a turning, breathing frame (rheonomic T2, T1, T0; V(q, t)).")
