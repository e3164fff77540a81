"""Planar double pendulum: absolute angles th1, th2 from the downward vertical, point masses m1, m2
on massless rods l1, l2."""
import sympy as sp

from lagrange_gen import Drawing, Model, coordinates, parameters

th1, th2 = coordinates("th1 th2")
m1, m2, l1, l2, g = parameters("m1 m2 l1 l2 g", defaults=(1.0, 1.0, 1.0, 1.0, 9.81))

x1, y1 = l1 * sp.sin(th1), -l1 * sp.cos(th1)
x2, y2 = x1 + l2 * sp.sin(th2), y1 - l2 * sp.cos(th2)
v1sq = (l1 * th1.d) ** 2
v2sq = v1sq + (l2 * th2.d) ** 2 + 2 * l1 * l2 * th1.d * th2.d * sp.cos(th1 - th2)

T = m1 * v1sq / 2 + m2 * v2sq / 2
V = m1 * g * y1 + m2 * g * y2

model = Model("double_pendulum", coords=[th1, th2], T=T, V=V,
              description="Planar double pendulum in absolute angles.",
              draw=Drawing(points={"pivot": (0, 0), "m1": (x1, y1), "m2": (x2, y2)},
                           segments=[("pivot", "m1"), ("m1", "m2")]))
