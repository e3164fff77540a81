"""The cart pendulum of models/cart_pendulum.py (spring-restrained cart mass M, bob m on a
massless rod l, theta from the downward vertical) with a horizontal force u on the cart: an
input (Model inputs=), given by a controller, a Signal or params, so that lg.linearize has a B
column and the LQR story of docs/guides/time-and-inputs.md runs on the getting-started model."""
import sympy as sp

from lagrange_gen import Drawing, Model, coordinates, inputs, parameters

x, th = coordinates("x theta")
M, m, l, k, g = parameters("M m l k g", defaults=(1.0, 0.5, 1.0, 10.0, 9.81))
u = inputs("u", defaults=0.0)      # no force unless a controller or a signal gives one

T = (M + m) * x.d**2 / 2 + m * l * x.d * th.d * sp.cos(th) + m * l**2 * th.d**2 / 2
V = k * x**2 / 2 - m * g * l * sp.cos(th)

model = Model("cart_pendulum_forced", coords=[x, th], T=T, V=V, forces={x: u}, inputs=[u],
              description="Pendulum on a spring-restrained cart pushed by the input u.",
              draw=Drawing(points={"cart": (x, 0), "bob": (x + l * sp.sin(th), -l * sp.cos(th))},
                           segments=[("cart", "bob")]))
