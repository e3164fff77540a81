"""Test model: torque_pendulum with the pendulum's inertia modulated in time,
m l^2 (1 + a sin(w t)): H depends on t (T2(q, t)) with no term linear in the velocities, so the
step Jacobians of the momentum-form methods see H(q, t) at every time they evaluate it."""
import sympy as sp

from lagrange_gen import Model, coordinates, inputs, parameters, t

x, th = coordinates("x theta")
M, m, l, k, g, a, w = parameters("M m l k g a w", defaults=(1.0, 0.5, 0.8, 10.0, 9.81, 0.6, 7.0))
u = inputs("u")

T = ((M + m) * x.d**2 / 2 + m * l * x.d * th.d * sp.cos(th)
     + m * l**2 * (1 + a * sp.sin(w * t)) * th.d**2 / 2)
V = k * x**2 / 2 - m * g * l * sp.cos(th)

model = Model("modulated_pendulum", coords=[x, th], T=T, V=V, forces={th: u * sp.cos(x)},
              inputs=[u])
