"""A puck on an inclined plane with Coulomb friction in 3D: a point mass at (x, y, z) in the
inertial frame N, the plane through the origin with unit normal n = sin(a) N.x + cos(a) N.z
(downhill towards +x), built by Contact.point_on_plane with the plane's tangents taken from N
(tangents="frame": t1 = N.y, across the slope; t2 = n x N.y, up the slope).

Launched sideways (along N.y) it slides on a curving path: friction opposes the slip direction,
gravity pulls downhill. For tan(a) < mu it comes to rest and stays; the energy balance
E - E0 - W, W the friction's work, closes."""
import sympy as sp
import sympy.physics.mechanics as me

from lagrange_gen import Contact, Model, parameters

x, y, z = me.dynamicsymbols("x y z")
m, g, a, mu = parameters("m g a mu", defaults=(1.0, 9.81, 0.3, 0.5))
N = me.ReferenceFrame("N")
O = me.Point("O")
O.set_vel(N, 0)
P = O.locatenew("P", x * N.x + y * N.y + z * N.z)
normal = sp.sin(a) * N.x + sp.cos(a) * N.z
velocity = P.pos_from(O).dt(N)

model = Model("puck_on_incline", coords=[x, y, z], T=m * velocity.dot(velocity) / 2,
              V=m * g * z,
              contacts=[Contact.point_on_plane(P, O, N, normal, tangents="frame", restitution=0,
                                               friction=mu, name="incline")],
              description="Puck sliding on an inclined plane: Coulomb's friction disk (3D).")
