"""Slider-crank hitting an end stop, written in the crank angle th and the slider position x
with the loop closure as a holonomic constraint: the same mechanism as
models/slider_crank_stop.py (one coordinate, the closure solved in closed form), whose runs it
must reproduce to the methods' order.

Crank of length r (inertia J about its pivot) at the origin, massless connecting rod of length L
from the crank pin (r cos th, r sin th) to the slider of mass m at (x, 0), a constant torque tau
on the crank. The rod's length is the constraint (x - r cos th)^2 + (r sin th)^2 - L^2 = 0
(halved); the stop at x_stop < r + L is written in the slider coordinate: gap = x_stop - x >= 0,
restitution e."""
import sympy as sp

from lagrange_gen import Contact, Model, coordinates, parameters

th, x = coordinates("th x")
r, L, J, m, tau, x_stop, e = parameters("r L J m tau x_stop e",
                                        defaults=(0.3, 1.0, 0.05, 1.0, -1.0, 1.25, 1.0))

model = Model("slider_crank_stop_constrained", coords=[th, x],
              T=J * th.d**2 / 2 + m * x.d**2 / 2, V=-tau * th,
              constraints=[((x - r * sp.cos(th))**2 + (r * sp.sin(th))**2 - L**2) / 2],
              contacts=[Contact(gap=x_stop - x, restitution=e, name="end_stop")],
              description="Slider-crank (crank angle th, slider x, loop closure as a constraint) "
                          "whose slider hits an end stop at x_stop (restitution e).")
