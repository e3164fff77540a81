"""models/heavy_top.py written with sympy.physics.mechanics: a RigidBody for T, gravity as a
Force at the centre of mass (converted by virtual work), the frame A in ZXZ Euler angles."""
import sympy.physics.mechanics as me

import lagrange_gen as lg
from lagrange_gen import Model, parameters

theta, phi, psi = me.dynamicsymbols("theta phi psi")
I1, I3, m, g, l = parameters("I1 I3 m g l", defaults=(1.0, 0.5, 1.0, 9.81, 0.5))

N = me.ReferenceFrame("N")
A = N.orientnew("A", "Body", [phi, theta, psi], "ZXZ")     # A.z: the symmetry axis
O = me.Point("O")
O.set_vel(N, 0)                                             # the fixed tip
G = O.locatenew("G", l * A.z)                               # centre of mass
top = me.RigidBody("top", G, A, m, (me.inertia(A, I1, I1, I3), O))

model = Model("heavy_top_mechanics", coords=[theta, phi, psi], T=lg.kinetic_energy(N, top),
              forces=[me.Force(G, -m * g * N.z)], frame=N)
