"""Pendulum whose pivot is driven vertically, y0(t) = a sin(w t) (Kapitza's pendulum).

theta is measured from the downward vertical; the pivot's motion is a prescribed coordinate, so
T = T2 + T1 + T0 is rheonomic (T1 = m l y0' sin(theta) theta', T0 = m y0'^2 / 2). For fast
forcing (w much larger than sqrt(g/l)) the inverted position theta = pi is stable when
a^2 w^2 > 2 g l (Kapitza 1951; Landau-Lifshitz, Mechanics, sec. 30).
"""
import sympy as sp

from lagrange_gen import Model, coordinates, parameters, t

th, y0 = coordinates("theta y0")
m, l, g, a, w = parameters("m l g a w", defaults=(1.0, 1.0, 9.81, 0.05, 100.0))

# Bob at (l sin th, y0 - l cos th).
vx = l * sp.cos(th) * th.d
vy = y0.d + l * sp.sin(th) * th.d
T = m * (vx**2 + vy**2) / 2
V = m * g * (y0 - l * sp.cos(th))

model = Model("driven_pendulum", coords=[th], T=T, V=V, prescribed={y0: a * sp.sin(w * t)},
              description="Kapitza pendulum: pivot driven vertically, y0 = a sin(w t).")
