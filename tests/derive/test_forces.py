"""Generalized forces: point forces by virtual work, Rayleigh dissipation, time-dependent forcing."""

import sympy as sp

from lagrange_gen import Model, PointForce, coordinates, parameters, t
from lagrange_gen.derive import derive


def test_point_force_by_virtual_work_on_a_pendulum():
    th = coordinates("th")
    m, l, F = parameters("m l F", defaults=(1.0, 2.0, 0.5))
    bob = (l * sp.sin(th), -l * sp.cos(th))
    model = Model("forced", coords=[th], T=m * l**2 * th.d**2 / 2,
                  forces=[PointForce(bob, (F * sp.cos(t), 0))])
    dyn = derive(model)
    # delta W = F cos(t) * d(l sin th) = F cos(t) l cos(th) delta th
    assert sp.simplify(dyn.Q[0] - F * sp.cos(t) * l * sp.cos(th)) == 0


def test_rayleigh_dissipation_and_dict_forces():
    x, y = coordinates("x y")
    m, c, F = parameters("m c F", defaults=(1.0, 0.3, 1.0))
    model = Model("damped", coords=[x, y], T=m * (x.d**2 + y.d**2) / 2,
                  dissipation=c * (x.d - y.d) ** 2 / 2, forces={y: F * sp.sin(t)})
    dyn = derive(model)
    assert sp.expand(dyn.Q[0] + c * (x.d - y.d)) == 0
    assert sp.expand(dyn.Q[1] - c * (x.d - y.d) - F * sp.sin(t)) == 0
    assert not dyn.forces_velocity_free and dyn.mass_is_constant
