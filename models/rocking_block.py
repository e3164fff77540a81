"""Rocking block (Housner 1963): a rigid rectangular block of half-width b and half-height c on
rigid ground, centre of mass at (x, y), tilted by phi (counter-clockwise), its two bottom corners
in unilateral contact with the ground (restitution e, Coulomb friction mu). The ground
accelerates horizontally with a_ground: in the ground's frame a constant inertial force
-m a_ground acts along x.

Corner s = -1 (left), +1 (right) is at (x + s b cos phi + c sin phi, y + s b sin phi - c cos phi).
Housner: with friction enough to prevent sliding the block starts rocking when
a_ground > g b / c (= g tan alpha, alpha = atan(b / c)), else it stays; a plastic impact (e = 0)
on the other corner keeps the fraction r = (1 - 3/2 sin^2 alpha)^2 of the kinetic energy
(angular momentum about the new corner conserved, I = m (b^2 + c^2) / 3 about the centre)."""
from lagrange_gen import Contact, Model, coordinates, parameters
import sympy as sp

x, y, phi = coordinates("x y phi")
m, g, b, c, e, mu, a_ground = parameters("m g b c e mu a_ground",
                                         defaults=(1.0, 9.81, 0.2, 0.6, 0.0, 1.0, 0.0))

inertia = m * (b**2 + c**2) / 3


def _corner(s):
    """The contact of corner s (-1 left, +1 right): gap = its height, slip = its x velocity."""
    height = y + s * b * sp.sin(phi) - c * sp.cos(phi)
    slip = x.d + (-s * b * sp.sin(phi) + c * sp.cos(phi)) * phi.d
    return Contact(gap=height, restitution=e, friction=mu, slip=slip,
                   name="left_corner" if s < 0 else "right_corner")


model = Model("rocking_block", coords=[x, y, phi],
              T=m * (x.d**2 + y.d**2) / 2 + inertia * phi.d**2 / 2,
              V=m * g * y + m * a_ground * x,
              contacts=[_corner(-1), _corner(1)],
              description="Rectangular block rocking on its corners (Housner), ground "
                          "acceleration a_ground.")
