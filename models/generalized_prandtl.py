"""Generalized Prandtl model with linear hardening and a dashpot (HARD_CASES case 10 and the
identification experiment): m x'' + c x' + k0 x + sum_i k_i u_i = F(t), u_i' + dpsi_[-eta_i,
eta_i](u_i) ∋ x', F = f cos(omega t). Defaults: n = 3, k0 = k_i = 1/3, eta_i = i, c = 0.3,
f = 4, omega = 0.05. `build(n)` gives n elements (eta_i = i, k_i = 1/3)."""
import sympy as sp

from lagrange_gen import Model, SaintVenant, coordinates, parameters, t


def generalized_prandtl(n=3):
    n = int(n)
    if n < 1:
        raise ValueError(f"generalized_prandtl: n must be >= 1, got {n}")
    x = coordinates("x")
    m, c, k0, f, omega = parameters("m c k0 f omega", defaults=(1.0, 0.3, 1 / 3, 4.0, 0.05))
    ks = parameters(" ".join(f"k{i}" for i in range(1, n + 1)), defaults=[1 / 3] * n)
    etas = parameters(" ".join(f"eta{i}" for i in range(1, n + 1)), defaults=list(range(1, n + 1)))
    ks, etas = (ks, etas) if n > 1 else ([ks], [etas])
    elements = [SaintVenant(strain=x, stiffness=k, threshold=e, name=f"slider{i + 1}")
                for i, (k, e) in enumerate(zip(ks, etas))]
    return Model("generalized_prandtl" if n == 3 else f"generalized_prandtl_{n}", coords=[x],
                 T=m * x.d**2 / 2, V=k0 * x**2 / 2, dissipation=c * x.d**2 / 2,
                 forces=[f * sp.cos(omega * t)], elements=elements,
                 description=f"Generalized Prandtl model, {n} Saint-Venant elements, hardening, dashpot.")


build = generalized_prandtl
model = generalized_prandtl(3)
