"""Planar four-bar linkage (a closed loop): crank, coupler and rocker as uniform rods under gravity.

Absolute link angles th1 (crank, pivot A = (0, 0)), th2 (coupler), th3 (rocker, pivot D = (d, 0)),
measured from the x axis; two loop-closure constraints tie them, one degree of freedom is left.
Defaults a = 1, b = 3, c = 2.5, d = 3 satisfy Grashof's condition with the crank as shortest
link (a + b < c + d): a crank-rocker whose crank turns fully and whose constraint Jacobian keeps
full rank everywhere. H(q) is not constant (the coupler's kinetic energy couples th1 and th2),
so rattle runs its Newton path here.
"""
import sympy as sp

from lagrange_gen import Drawing, Model, coordinates, parameters

th1, th2, th3 = coordinates("th1 th2 th3")
a, b, c, d, m1, m2, m3, g = parameters("a b c d m1 m2 m3 g",
                                       defaults=(1.0, 3.0, 2.5, 3.0, 1.0, 1.0, 1.0, 9.81))

# Centre of the coupler: crank tip plus half the coupler.
vx2 = -a * sp.sin(th1) * th1.d - b / 2 * sp.sin(th2) * th2.d
vy2 = a * sp.cos(th1) * th1.d + b / 2 * sp.cos(th2) * th2.d
T = (m1 * a**2 / 3 * th1.d**2 / 2 + m3 * c**2 / 3 * th3.d**2 / 2
     + m2 * (vx2**2 + vy2**2) / 2 + m2 * b**2 / 12 * th2.d**2 / 2)
V = g * (m1 * a / 2 * sp.sin(th1) + m2 * (a * sp.sin(th1) + b / 2 * sp.sin(th2))
         + m3 * c / 2 * sp.sin(th3))
Phi = [a * sp.cos(th1) + b * sp.cos(th2) - c * sp.cos(th3) - d,
       a * sp.sin(th1) + b * sp.sin(th2) - c * sp.sin(th3)]

model = Model("four_bar", coords=[th1, th2, th3], T=T, V=V, constraints=Phi,
              description="Four-bar crank-rocker linkage in absolute angles, two loop constraints.",
              # C is drawn from both sides (coupler end, rocker end): a drift shows as a gap
              draw=Drawing(points={"A": (0, 0), "B": (a * sp.cos(th1), a * sp.sin(th1)),
                                   "C": (a * sp.cos(th1) + b * sp.cos(th2), a * sp.sin(th1) + b * sp.sin(th2)),
                                   "C_rocker": (d + c * sp.cos(th3), c * sp.sin(th3)), "D": (d, 0)},
                           segments=[("A", "B"), ("B", "C"), ("C_rocker", "D"), ("D", "A")]))
