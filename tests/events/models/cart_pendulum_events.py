"""The cart pendulum of models/cart_pendulum.py with two events: the bob passes the vertical
(theta = 0, both directions) and the cart stops while moving right (x' falls through 0)."""
import sympy as sp

from lagrange_gen import Event, Model, coordinates, parameters

x, th = coordinates("x theta")
M, m, l, k, g = parameters("M m l k g", defaults=(1.0, 0.5, 1.0, 10.0, 9.81))

T = (M + m) * x.d**2 / 2 + m * l * x.d * th.d * sp.cos(th) + m * l**2 * th.d**2 / 2
V = k * x**2 / 2 - m * g * l * sp.cos(th)

model = Model("cart_pendulum_events", coords=[x, th], T=T, V=V,
              events={"vertical": th, "cart_stops": Event(x.d, direction=-1)})
