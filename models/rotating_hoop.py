"""Bead on a hoop of radius R that turns at the constant rate w about its vertical diameter.

theta is measured from the bottom of the hoop. In the turning frame T = T2 + T0 with
T2 = m R^2 theta'^2 / 2 and T0 = m R^2 w^2 sin(theta)^2 / 2 (the centrifugal potential
-T0); L has no explicit t, so the energy function E = T2 - T0 + V (the Jacobi integral) is
conserved although T + V is not. Equilibria: theta = 0, stable for w^2 < g/R; past the
bifurcation w^2 = g/R it is unstable and theta* = arccos(g / (R w^2)) is stable, with small
oscillations at Omega^2 = w^2 sin(theta*)^2 (at theta = 0: Omega^2 = g/R - w^2).
"""
import sympy as sp

from lagrange_gen import Model, coordinates, parameters, t

th, phi = coordinates("theta phi")
m, R, g, w = parameters("m R g w", defaults=(1.0, 1.0, 9.81, 5.0))

# The bead at R (sin th cos phi, sin th sin phi, -cos th) with the hoop's angle phi = w t.
x = R * sp.sin(th) * sp.cos(phi)
y = R * sp.sin(th) * sp.sin(phi)
z = -R * sp.cos(th)
speed2 = sp.trigsimp(sp.expand(sum((sp.diff(c, th) * th.d + sp.diff(c, phi) * phi.d)**2
                                     for c in (x, y, z))))
model = Model("rotating_hoop", coords=[th], T=m * speed2 / 2, V=m * g * z,
              prescribed={phi: w * t},
              description="Bead on a hoop turning at rate w about its vertical diameter.")
