"""Block on a ramp with Coulomb friction: a point mass at (X, Y) on the plane through the origin
inclined at angle a (going down towards +X), released at rest on it.

gap = distance to the plane = X sin a + Y cos a; slip = velocity along the plane, downhill,
X' cos a - Y' sin a. It sticks for tan a <= mu; otherwise it slides with the constant
acceleration g (sin a - mu cos a), s(t) = g (sin a - mu cos a) t^2 / 2 along the plane."""
from lagrange_gen import Contact, Model, coordinates, parameters
import sympy as sp

X, Y = coordinates("X Y")
m, g, a, mu = parameters("m g a mu", defaults=(1.0, 9.81, 0.5, 0.3))

model = Model("block_on_ramp", coords=[X, Y], T=m * (X.d**2 + Y.d**2) / 2, V=m * g * Y,
              contacts=[Contact(gap=X * sp.sin(a) + Y * sp.cos(a), restitution=0, friction=mu,
                                slip=X.d * sp.cos(a) - Y.d * sp.sin(a), name="ramp")],
              description="Block on an inclined plane (angle a) with Coulomb friction mu.")
