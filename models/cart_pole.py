"""Inverted pendulum on a cart driven by a horizontal force u (the LQR example): cart mass M,
bob m on a massless rod l, viscous friction c on the cart, theta measured from the upward
vertical (theta = 0 is the inverted equilibrium). Outputs: the cart position and the angle."""
import sympy as sp

from lagrange_gen import Model, coordinates, inputs, parameters

x, th = coordinates("x theta")
M, m, l, g, c = parameters("M m l g c", defaults=(1.0, 0.3, 0.5, 9.81, 0.1))
u = inputs("u", defaults=0.0)      # no force unless a controller or a signal gives one

T = (M + m) * x.d**2 / 2 + m * l * x.d * th.d * sp.cos(th) + m * l**2 * th.d**2 / 2
V = m * g * l * sp.cos(th)

model = Model("cart_pole", coords=[x, th], T=T, V=V, forces={x: u - c * x.d}, inputs=[u],
              outputs={"cart": x, "tip_x": x + l * sp.sin(th)},
              description="Inverted pendulum on a cart pushed by the input u (LQR example).")
