"""A ball (height y of its lowest point) bouncing on a table whose height moves with time,
h(t) = w t + A sin(Omega t): a rheonomic gap y - h(t) >= 0 with restitution e.

Newton's law acts on the velocity relative to the table: y'+ - h'(t) = -e (y'- - h'(t)). For
A = 0 (a table rising at the constant speed w) the motion relative to the table is the ball on
a fixed floor (Galilean invariance): relative rebound speeds fall by e at each impact."""
import sympy as sp

from lagrange_gen import Contact, Model, coordinates, parameters, t

y = coordinates("y")
m, g, e, w, A, Omega = parameters("m g e w A Omega", defaults=(1.0, 9.81, 0.8, 0.5, 0.0, 5.0))

model = Model("ball_on_moving_table", coords=[y], T=m * y.d**2 / 2, V=m * g * y,
              contacts=[Contact(gap=y - w * t - A * sp.sin(Omega * t), restitution=e,
                                name="table")],
              description="Ball bouncing on a moving table (rheonomic contact).")
