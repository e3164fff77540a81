"""Pendulum on a spring-restrained cart (MEAM 535 notes): cart mass M, bob m on a massless rod l,
spring k with zero free length, theta measured from the downward vertical."""
import sympy as sp

from lagrange_gen import Drawing, Model, coordinates, parameters

x, th = coordinates("x theta")
M, m, l, k, g = parameters("M m l k g", defaults=(1.0, 0.5, 1.0, 10.0, 9.81))

T = (M + m) * x.d**2 / 2 + m * l * x.d * th.d * sp.cos(th) + m * l**2 * th.d**2 / 2
V = k * x**2 / 2 - m * g * l * sp.cos(th)

model = Model("cart_pendulum", coords=[x, th], T=T, V=V,
              description="Pendulum on a spring-restrained cart (MEAM 535).",
              draw=Drawing(points={"cart": (x, 0), "bob": (x + l * sp.sin(th), -l * sp.cos(th))},
                           segments=[("cart", "bob")]))
