"""Slider-crank hitting an end stop: the crank angle th the one coordinate (the loop closure
solved in closed form), the slider's travel bounded by a stop.

Crank of length r (inertia J about its pivot) at the origin, massless connecting rod of length L
to a slider of mass m at x(th) = r cos th + sqrt(L^2 - r^2 sin^2 th) on the x axis, a constant
torque tau on the crank. The stop at x_stop < r + L bounds the slider: gap = x_stop - x(th) >= 0,
restitution e. With one coordinate, Newton's law at the stop reverses the crank's rate:
th'+ = -e th'- (the impulse acts along dgap/dth); e = 1 keeps the energy
E = (J + m x'(th)^2) th'^2 / 2 - tau th, e = 0 stops the slider (x' th' = 0) and, with tau
pushing it on, holds it against the stop."""
import sympy as sp

from lagrange_gen import Contact, Model, coordinates, parameters

th = coordinates("th")
r, L, J, m, tau, x_stop, e = parameters("r L J m tau x_stop e",
                                        defaults=(0.3, 1.0, 0.05, 1.0, -1.0, 1.25, 1.0))

x = r * sp.cos(th) + sp.sqrt(L**2 - r**2 * sp.sin(th)**2)
x_dot = sp.diff(x, th) * th.d

model = Model("slider_crank_stop", coords=[th], T=J * th.d**2 / 2 + m * x_dot**2 / 2,
              V=-tau * th, contacts=[Contact(gap=x_stop - x, restitution=e, name="end_stop")],
              description="Slider-crank (crank angle th, torque tau) whose slider hits an end "
                          "stop at x_stop (restitution e).")
