"""Stretchable pendulum (HARD_CASES case 7): a bob on a spring of stiffness k and rest length l,
in Cartesian coordinates. As k -> inf it tends to the rigid pendulum (models/cartesian_pendulum.py
with |x| = l as a constraint); the radial mode has omega = sqrt(k / m), so explicit methods need
h omega < 2 while implicit ones stay stable at any k."""
import sympy as sp

from lagrange_gen import Model, coordinates, parameters

x, y = coordinates("x y")
m, l, g, k = parameters("m l g k", defaults=(1.0, 1.0, 9.81, 1e4))

T = m * (x.d**2 + y.d**2) / 2
V = m * g * y + k / 2 * (sp.sqrt(x**2 + y**2) - l)**2

model = Model("stretchable_pendulum", coords=[x, y], T=T, V=V,
              description="Bob on a stiff spring (rest length l): the rigid pendulum as k -> inf.")
