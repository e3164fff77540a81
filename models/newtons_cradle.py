"""Newton's cradle on a rail: three equal balls (mass m, radius r) on a frictionless line, at
x1 < x2 < x3, with Newton restitution e between neighbours (the straight-line cradle: the
pendulum strings only bring the balls back, they take no part in the impacts).

Ball 1 hits balls 2 and 3 while they touch: two contacts close at once. Moreau-Jean resolves
them as one simultaneous impact (Newton's law on both gaps, complementarity): with V the speed
of ball 1, velocities after (1 - 2e) V / 3, (1 + e) V / 3, (1 + e) V / 3, which for e = 1
conserves the energy but is not the toy's (0, 0, V), the result of two separate impacts (which
it gives when the balls are apart)."""
from lagrange_gen import Contact, Model, coordinates, parameters

x1, x2, x3 = coordinates("x1 x2 x3")
m, r, e = parameters("m r e", defaults=(1.0, 0.1, 1.0))

model = Model("newtons_cradle", coords=[x1, x2, x3], T=m * (x1.d**2 + x2.d**2 + x3.d**2) / 2,
              contacts=[Contact(gap=x2 - x1 - 2 * r, restitution=e, name="balls_1_2"),
                        Contact(gap=x3 - x2 - 2 * r, restitution=e, name="balls_2_3")],
              description="Newton's cradle: three balls on a line with restitution e.")
