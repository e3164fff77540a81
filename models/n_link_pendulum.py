"""Planar n-link pendulum of point masses on massless rods, absolute angles from the downward
vertical. `n_link_pendulum(n)` builds the model; `lagrange-gen models/n_link_pendulum.py --set n=8`
generates generated/n_link_pendulum_8.py. The file's default `model` has n = 3."""
import sympy as sp

from lagrange_gen import Drawing, Model, coordinates, parameters


def n_link_pendulum(n=3):
    n = int(n)
    if n < 1:
        raise ValueError(f"n_link_pendulum: n must be >= 1, got {n}")
    th = coordinates(" ".join(f"th{i}" for i in range(1, n + 1)))
    th = th if isinstance(th, list) else [th]
    m, l, g = parameters("m l g", defaults=(1.0, 1.0, 9.81))
    # Velocities of the masses are sums of link velocities; T is written as sum of squares of
    # those sums so its Hessian is H directly, with no expansion.
    x = y = vx = vy = 0
    T = V = 0
    points = {"pivot": (0, 0)}
    for k in range(n):
        x += l * sp.sin(th[k])
        y -= l * sp.cos(th[k])
        points[f"m{k + 1}"] = (x, y)
        vx += l * sp.cos(th[k]) * th[k].d
        vy += l * sp.sin(th[k]) * th[k].d
        T += m * (vx**2 + vy**2) / 2
        V += m * g * y
    return Model(f"n_link_pendulum_{n}", coords=th, T=T, V=V,
                 description=f"Planar {n}-link pendulum, equal point masses and rods.",
                 draw=Drawing(points, segments=list(zip(points, list(points)[1:]))))


build = n_link_pendulum
model = n_link_pendulum(3)
