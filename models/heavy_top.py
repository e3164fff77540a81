"""Heavy symmetric top with a fixed tip, Euler angles (theta nutation from the upward vertical,
phi precession, psi spin): moments of inertia I1 = I2 about the tip and I3 about the symmetry
axis, mass m, centre of mass at distance l from the tip. phi and psi are cyclic."""
import sympy as sp

from lagrange_gen import Drawing, Model, coordinates, parameters

theta, phi, psi = coordinates("theta phi psi")
I1, I3, m, g, l = parameters("I1 I3 m g l", defaults=(1.0, 0.5, 1.0, 9.81, 0.5))

T = (I1 * (theta.d**2 + phi.d**2 * sp.sin(theta)**2) / 2
     + I3 * (psi.d + phi.d * sp.cos(theta))**2 / 2)
V = m * g * l * sp.cos(theta)

# z-x-z Euler angles: the symmetry axis e3 and a body axis e1 (the spin shows as e1 turning)
e3 = (sp.sin(theta) * sp.sin(phi), -sp.sin(theta) * sp.cos(phi), sp.cos(theta))
e1 = (sp.cos(phi) * sp.cos(psi) - sp.sin(phi) * sp.sin(psi) * sp.cos(theta),
      sp.sin(phi) * sp.cos(psi) + sp.cos(phi) * sp.sin(psi) * sp.cos(theta),
      sp.sin(psi) * sp.sin(theta))
centre = tuple(l * c for c in e3)
model = Model("heavy_top", coords=[theta, phi, psi], T=T, V=V,
              description="Heavy symmetric top in Euler angles (Lagrange top).",
              draw=Drawing(points={"tip": (0, 0, 0), "centre": centre,
                                   "rim": tuple(r + l / 2 * c for r, c in zip(centre, e1))},
                           segments=[("tip", "centre"), ("centre", "rim")]))
