"""Chaplygin sleigh (models/chaplygin_sleigh.py) whose centre of mass is held by a spring of
stiffness k to the origin: V = k (x^2 + y^2) / 2. The knife edge keeps turning the sleigh and the
spring keeps it moving, so the motion never settles into a straight line, and the energy
E = T + V is conserved by the exact flow (the constraint is scleronomic, the forces
conservative): the long-run test of what a nonholonomic method does to the energy."""
import sympy as sp

from lagrange_gen import Model, coordinates, parameters

x, y, theta = coordinates("x y theta")
m, I, a, k = parameters("m I a k", defaults=(1.0, 0.2, 0.5, 1.0))

model = Model("sleigh_in_well", coords=[x, y, theta],
              T=m * (x.d**2 + y.d**2) / 2 + I * theta.d**2 / 2, V=k * (x**2 + y**2) / 2,
              nonholonomic=[-sp.sin(theta) * x.d + sp.cos(theta) * y.d - a * theta.d],
              description="Chaplygin sleigh in a harmonic well (nonholonomic, conservative).")
