"""Vertical disk rolling without slipping on a horizontal plane (Bloch, "Nonholonomic Mechanics
and Control", sec. 1.4): contact point (x, y), heading phi, rolling angle theta, radius R, mass
m, moments I_spin (about the axle) and I_turn (about the vertical diameter).

Rolling: the contact point's material velocity is zero, x' = R theta' cos(phi),
y' = R theta' sin(phi) (two nonholonomic constraints). Lagrange-d'Alembert gives
(I_spin + m R^2) theta'' = 0 and I_turn phi'' = 0: theta' = omega and phi' = Omega stay
constant and the disk rolls on a circle of radius rho = R omega / Omega at the speed R omega,
held on it by the constraint force m (R omega) Omega towards the centre (the multipliers are the
horizontal force on the disk, (mu_x, mu_y) = m (x'', y'')). Energy
E = m R^2 omega^2 / 2 + I_spin omega^2 / 2 + I_turn Omega^2 / 2 is conserved."""
import sympy as sp

from lagrange_gen import Model, coordinates, parameters

x, y, phi, theta = coordinates("x y phi theta")
m, R, I_spin, I_turn = parameters("m R I_spin I_turn", defaults=(1.0, 0.5, 0.125, 0.0625))

model = Model("rolling_disk", coords=[x, y, phi, theta],
              T=m * (x.d**2 + y.d**2) / 2 + I_spin * theta.d**2 / 2 + I_turn * phi.d**2 / 2,
              nonholonomic=[x.d - R * sp.cos(phi) * theta.d, y.d - R * sp.sin(phi) * theta.d],
              description="Vertical disk rolling without slipping on a plane (nonholonomic).")
