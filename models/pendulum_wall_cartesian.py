"""A pendulum in Cartesian coordinates (x, y) of its bob, on a rod of length l
(x^2 + y^2 = l^2, a holonomic constraint), swinging into a wall x <= a (a < l), restitution e.

The same pendulum in its angle th (x = l sin th, y = -l cos th) meets the wall at
sin th_w = a / l; released at rest from th0 < th_w, it gets there with
th'_w^2 = 2 g (cos th_w - cos th0) / l after t_w = integral from th0 to th_w of dth / th'(th),
and Newton's law on the gap a - x (normal velocity -l cos th th') leaves with th'+ = -e th'_w."""
from lagrange_gen import Contact, Model, coordinates, parameters

x, y = coordinates("x y")
m, l, g, a, e = parameters("m l g a e", defaults=(1.0, 1.0, 9.81, 0.5, 0.8))

model = Model("pendulum_wall_cartesian", coords=[x, y], T=m * (x.d**2 + y.d**2) / 2,
              V=m * g * y, constraints=[(x**2 + y**2 - l**2) / 2],
              contacts=[Contact(gap=a - x, restitution=e, name="wall")],
              description="Pendulum in Cartesian coordinates (rod constraint) hitting a wall "
                          "x = a (restitution e).")
