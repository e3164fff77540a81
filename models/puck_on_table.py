"""A puck sliding on a horizontal table z = 0 with Coulomb friction in 3D: a point mass at
(x, y, z), gap z, slip velocities (x', y') (the two tangents of the table: the friction disk).

From a horizontal velocity v0 it slides in a straight line along v0, decelerating at mu g, and
stops at the distance v0^2 / (2 mu g) at the time v0 / (mu g), whatever the direction of v0 (a
box-shaped friction law, |p_x|, |p_y| <= mu p_N each, would bend the path towards a diagonal)."""
from lagrange_gen import Contact, Model, coordinates, parameters

x, y, z = coordinates("x y z")
m, g, mu = parameters("m g mu", defaults=(1.0, 9.81, 0.3))

model = Model("puck_on_table", coords=[x, y, z], T=m * (x.d**2 + y.d**2 + z.d**2) / 2,
              V=m * g * z,
              contacts=[Contact(gap=z, restitution=0, friction=mu, slip=(x.d, y.d), name="table")],
              description="Puck sliding on a table: Coulomb's friction disk (3D).")
