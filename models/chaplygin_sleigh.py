"""Chaplygin sleigh: a rigid body on a plane (centre of mass (x, y), heading theta, mass m,
inertia I about the centre of mass) supported by a knife edge at distance a behind the centre of
mass, which cannot slide sideways (Bloch, "Nonholonomic Mechanics and Control", sec. 1.7).

No sideslip at the knife edge P = C - a (cos theta, sin theta):
-sin(theta) x' + cos(theta) y' - a theta' = 0. With u the forward velocity of the centre of mass
and w = theta', Lagrange-d'Alembert gives u' = a w^2, w' = -m a u w / (I + m a^2); the energy
E = m u^2 / 2 + (I + m a^2) w^2 / 2 is conserved, so with U = sqrt(2 E / m) and
k = m a U / (I + m a^2):

    u(t) = U tanh(k t + c),   w(t) = w(0) cosh(c) / cosh(k t + c),   c = atanh(u(0) / U):

the rotation dies out and the sleigh ends moving straight along its axis at the speed U."""
import sympy as sp

from lagrange_gen import Model, coordinates, parameters

x, y, theta = coordinates("x y theta")
m, I, a = parameters("m I a", defaults=(1.0, 0.2, 0.5))

model = Model("chaplygin_sleigh", coords=[x, y, theta],
              T=m * (x.d**2 + y.d**2) / 2 + I * theta.d**2 / 2,
              nonholonomic=[-sp.sin(theta) * x.d + sp.cos(theta) * y.d - a * theta.d],
              description="Chaplygin sleigh: knife edge behind the centre of mass (nonholonomic).")
