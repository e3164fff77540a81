"""Slider-crank driven at a prescribed crank angle th = w t, with a mass on a spring riding the
slider.

Crank of length r about the origin, connecting rod of length L from the crank pin to the
slider at (x, 0). The crank angle is prescribed (a motor), so the loop closure

    r cos(w t) + L cos(psi) - x = 0,    r sin(w t) - L sin(psi) = 0

is a pair of rheonomic constraints Phi(q, t) = 0 on the rod angle psi and the slider position x;
closed-form kinematics: x(t) = r cos(w t) + sqrt(L^2 - r^2 sin(w t)^2). A mass m3 on a spring
(stiffness k) rides the slider along its track, at x + y: the one free coordinate.
"""
import sympy as sp

from lagrange_gen import Model, coordinates, parameters, t

th, psi, x, y = coordinates("th psi x y")
r, L, w, m2, m3, k, c = parameters("r L w m2 m3 k c", defaults=(0.3, 1.0, 6.0, 1.0, 0.5, 40.0, 0.0))

# The rod (mass m2, uniform) in absolute terms: centre at the crank pin plus half the rod.
cx = r * sp.cos(th) + L / 2 * sp.cos(psi)
cy = r * sp.sin(th) - L / 2 * sp.sin(psi)
vc2 = sum((sp.diff(e, th) * th.d + sp.diff(e, psi) * psi.d)**2 for e in (cx, cy))
T = m2 * vc2 / 2 + m2 * L**2 / 12 * psi.d**2 / 2 + m2 * x.d**2 / 2 + m3 * (x.d + y.d)**2 / 2
V = k * y**2 / 2
Phi = [r * sp.cos(th) + L * sp.cos(psi) - x, r * sp.sin(th) - L * sp.sin(psi)]

model = Model("slider_crank", coords=[psi, x, y], T=T, V=V, constraints=Phi,
              dissipation=c * y.d**2 / 2, prescribed={th: w * t},
              description="Slider-crank with the crank angle prescribed (w t), spring mass on the slider.")
