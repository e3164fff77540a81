"""Chain of 4 masses between two walls joined by linear springs, with a linear dashpot from each
mass to ground (Rayleigh dissipation) and a sinusoidal force on the last mass."""
import sympy as sp

from lagrange_gen import Model, coordinates, parameters, t

N = 4
xs = coordinates(" ".join(f"x{i}" for i in range(1, N + 1)))
m, k, c, F0, w = parameters("m k c F0 w", defaults=(1.0, 100.0, 0.1, 1.0, 3.0))

T = sum(m * x.d**2 / 2 for x in xs)
ends = [0, *xs, 0]                       # fixed walls at both ends
V = sum(k * (ends[i + 1] - ends[i]) ** 2 / 2 for i in range(N + 1))
D = sum(c * x.d**2 / 2 for x in xs)

model = Model("spring_mass_chain", coords=xs, T=T, V=V, dissipation=D,
              forces={xs[-1]: F0 * sp.sin(w * t)},
              description="4-mass spring chain between walls, dashpots to ground, forced last mass.")
