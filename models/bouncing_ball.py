"""Bouncing ball: a point mass falling on the floor y = 0 under gravity, Newton restitution e.

Dropped from rest at height h0 it hits the floor at t_1 = sqrt(2 h0 / g) with speed
V_0 = sqrt(2 g h0); after the k-th impact it leaves with e^k V_0, rises to e^(2k) h0 and lands
again 2 e^k V_0 / g later. The impact times accumulate (a Zeno sequence) at
t_inf = t_1 + sum_k 2 e^k V_0 / g = sqrt(2 h0 / g) (1 + e) / (1 - e), where it comes to rest."""
from lagrange_gen import Contact, Model, coordinates, parameters

y = coordinates("y")
m, g, e = parameters("m g e", defaults=(1.0, 9.81, 0.8))

model = Model("bouncing_ball", coords=[y], T=m * y.d**2 / 2, V=m * g * y,
              contacts=[Contact(gap=y, restitution=e, name="floor")],
              description="Ball bouncing on the floor y = 0 (impacts with restitution e).")
