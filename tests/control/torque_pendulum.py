"""Test model: a pendulum (theta from the downward vertical) on a spring-restrained cart, a
torque u on the pendulum; rest at x = 0, m g l sin(theta) = u. Output: the height of the bob."""
import sympy as sp

from lagrange_gen import Model, coordinates, inputs, parameters

x, th = coordinates("x theta")
M, m, l, k, g = parameters("M m l k g", defaults=(1.0, 0.5, 0.8, 10.0, 9.81))
u = inputs("u")

T = (M + m) * x.d**2 / 2 + m * l * x.d * th.d * sp.cos(th) + m * l**2 * th.d**2 / 2
V = k * x**2 / 2 - m * g * l * sp.cos(th)

model = Model("torque_pendulum", coords=[x, th], T=T, V=V, forces={th: u * sp.cos(x)}, inputs=[u],
              outputs={"height": -l * sp.cos(th) + u * x**2, "speed": x.d * th.d})
