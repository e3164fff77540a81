"""Painleve's rod: a uniform rod (mass m, length 2 l) whose lower end slides on a rough floor,
the classic contact problem without a solution.

Coordinates: the centre (x, y) and the angle th of the rod above the horizontal; the lower end
is at (x - l cos th, y - l sin th), gap = y - l sin th, slip = x' + l sin th th'. With the end
sliding (slip direction s = sign(slip)) and a normal force N, the end's normal acceleration is

    g_N'' = (N / m) (1 + 3 cos^2 th + 3 mu s sin th cos th) - g + l sin th th'^2,

so for s = -1 and mu > (1 + 3 cos^2 th) / (3 sin th cos th) (2.5 at th = 30 degrees) a larger N
pulls the end down faster: at rest in th (th' = 0) under gravity no N >= 0 keeps g_N'' >= 0
(Painleve's paradox: no solution of the contact problem; the rod must jam, an impulsive
tangential impact, which rigid-body sliding cannot describe)."""
from lagrange_gen import Contact, Model, coordinates, parameters
import sympy as sp

x, y, th = coordinates("x y th")
m, l, g, mu, e = parameters("m l g mu e", defaults=(1.0, 0.5, 9.81, 3.0, 0.0))

model = Model("painleve_rod", coords=[x, y, th],
              T=m * (x.d**2 + y.d**2) / 2 + m * l**2 / 6 * th.d**2, V=m * g * y,
              contacts=[Contact(gap=y - l * sp.sin(th), restitution=e, friction=mu,
                                slip=x.d + l * sp.sin(th) * th.d, name="end")],
              description="Painleve's rod: its lower end sliding on a rough floor (no solution "
                          "of the contact problem for mu above (1 + 3 cos^2 th) / (3 sin th cos th)).")
