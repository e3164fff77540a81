"""Chaplygin sleigh dropped onto the floor: the knife edge's no-sideslip constraint (a velocity
constraint) beside a unilateral contact with impacts, which moreau_jean treats together.

The sleigh of models/chaplygin_sleigh.py (centre of mass (x, y), heading theta, knife edge at
distance a behind it: -sin(theta) x' + cos(theta) y' - a theta' = 0) with a height z above the
floor z = 0 (gravity g, Newton restitution e, no friction), the constraint held throughout (an
idealization: a skate on a vertical guide). The two motions do not couple: the horizontal one is
the sleigh's closed form (u = U tanh(k t + c), see models/chaplygin_sleigh.py), the vertical one
the bouncing ball's (first impact at sqrt(2 z0 / g), rebounds to e^2 z0)."""
import sympy as sp

from lagrange_gen import Contact, Model, coordinates, parameters

x, y, z, theta = coordinates("x y z theta")
m, I, a, g, e = parameters("m I a g e", defaults=(1.0, 0.2, 0.5, 9.81, 0.5))

model = Model("sleigh_drop", coords=[x, y, z, theta],
              T=m * (x.d**2 + y.d**2 + z.d**2) / 2 + I * theta.d**2 / 2, V=m * g * z,
              nonholonomic=[-sp.sin(theta) * x.d + sp.cos(theta) * y.d - a * theta.d],
              contacts=[Contact(gap=z, restitution=e, name="floor")],
              description="Chaplygin sleigh dropped onto the floor (a velocity constraint beside "
                          "a contact).")
