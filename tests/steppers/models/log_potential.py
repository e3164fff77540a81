"""A particle in the potential V = c log(x) (defined for x > 0): the force -c / x divides by zero
at x = 0, and log(x) is NaN for x < 0. Started at x = 0, or falling into it, a run must end in
BlowUp naming the step, never in a ZeroDivisionError from inside numba."""
import sympy as sp

from lagrange_gen import Model, coordinates, parameters

x = coordinates("x")
m, c = parameters("m c", defaults=(1.0, 1.0))

model = Model("log_potential", coords=[x], T=m * x.d**2 / 2, V=c * sp.log(x),
              description="Particle in V = c log(x) (singular at x = 0).")
