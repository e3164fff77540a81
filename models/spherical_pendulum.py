"""Spherical pendulum (MEAM 535 notes): q1 polar angle from the upward vertical, q2 azimuth.
H = diag(m l^2, m l^2 sin(q1)^2) is singular at sin(q1) = 0 (a coordinate singularity)."""
import sympy as sp

from lagrange_gen import Drawing, Model, coordinates, parameters

q1, q2 = coordinates("q1 q2")
m, l, g = parameters("m l g", defaults=(1.0, 1.0, 9.81))

T = m * l**2 * (q1.d**2 + sp.sin(q1) ** 2 * q2.d**2) / 2
V = m * g * l * sp.cos(q1)

model = Model("spherical_pendulum", coords=[q1, q2], T=T, V=V,
              description="Spherical pendulum, polar angle from the upward vertical.",
              draw=Drawing(points={"pivot": (0, 0, 0),
                                   "bob": (l * sp.sin(q1) * sp.cos(q2), l * sp.sin(q1) * sp.sin(q2),
                                           l * sp.cos(q1))},
                           segments=[("pivot", "bob")]))
