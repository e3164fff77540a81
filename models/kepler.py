"""Kepler problem in polar coordinates (r, phi): a mass m attracted to a fixed centre with
potential -k m / r (k = G M). E = -k m / (2 a), p_phi = m r^2 phi', period 2 pi a^1.5 / sqrt(k)."""
from lagrange_gen import Model, coordinates, parameters

r, phi = coordinates("r phi")
m, k = parameters("m k", defaults=(1.0, 1.0))

T = m * (r.d**2 + r**2 * phi.d**2) / 2
V = -k * m / r

model = Model("kepler", coords=[r, phi], T=T, V=V,
              description="Kepler problem in polar coordinates (r, phi).")
