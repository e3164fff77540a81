"""Viscoelastoplastic oscillator: mass, parallel spring k0, dashpot c, and a Saint-Venant element,
driven by F = f sin(omega t)."""
import sympy as sp

from lagrange_gen import Model, SaintVenant, coordinates, parameters, t

x = coordinates("x")
m, c, k0, k1, eta, f, omega = parameters("m c k0 k1 eta f omega",
                                         defaults=(1.0, 0.1, 0.5, 2.0, 0.5, 1.5, 0.8))

model = Model("viscoelastoplastic", coords=[x], T=m * x.d**2 / 2, V=k0 * x**2 / 2,
              dissipation=c * x.d**2 / 2, forces=[f * sp.sin(omega * t)],
              elements=[SaintVenant(strain=x, stiffness=k1, threshold=eta, name="slider")],
              description="Viscoelastoplastic oscillator (spring + dashpot + Saint-Venant element).")
