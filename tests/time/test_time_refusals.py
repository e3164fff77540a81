"""One-line refusals of the explicit-time inputs, each naming the symbol."""

import pytest
import sympy as sp

from lagrange_gen import Model, coordinates, parameters, t
from lagrange_gen.derive import derive
from lagrange_gen.errors import ModelError

x, y0, z = coordinates("x y0 z")
m, a, w = parameters("m a w", defaults=(1.0, 0.1, 3.0))
T = m * (x.d**2 + (y0.d + x.d) ** 2) / 2


@pytest.mark.parametrize("prescribed, message", [
    ({x: a * sp.sin(w * t)}, r"prescribed coordinate x is also in coords"),
    ({y0: a * x.d}, r"prescription of y0 uses the velocity x_d"),
    ({y0: a * z}, r"prescription of y0 uses the coordinate z"),
    ({y0: a * sp.Symbol("b")}, r"prescription of y0 uses the symbol b, which is neither"),
    ({a: sp.sin(t)}, r"prescribed key a is not a Coordinate"),
    ([y0], r"prescribed must be a dict"),
])
def test_prescription_refusals(prescribed, message):
    with pytest.raises(ModelError, match=message) as info:
        Model("bad", coords=[x], T=T, prescribed=prescribed)
    assert "\n" not in str(info.value)


def test_prescribed_coordinate_and_velocity_are_substituted():
    model = Model("driven", coords=[x], T=T, V=m * y0, prescribed={y0: a * sp.sin(w * t)})
    assert model.T == m * (x.d**2 + (a * w * sp.cos(w * t) + x.d) ** 2) / 2
    assert model.V == m * a * sp.sin(w * t)
    assert {s.name for s in model.params} == {"m", "a", "w"}


def test_degree_three_in_the_velocities_is_refused():
    with pytest.raises(ModelError, match=r"T is not quadratic in the velocities"):
        derive(Model("cubic", coords=[x], T=m * x.d**2 / 2 + x.d**3))


def test_velocity_dependent_constraint_is_refused_time_dependent_accepted():
    with pytest.raises(ModelError, match=r"constraint 0 .* depends on x_d"):
        Model("bad", coords=[x, z], T=T.subs(y0.d, 0) + z.d**2, constraints=[x - x.d])
    Model("ok", coords=[x, z], T=T.subs(y0.d, 0) + z.d**2, constraints=[x - z * sp.sin(t)])


def test_mass_that_turns_negative_in_time_names_t():
    """T = (1 - t) x'^2 / 2 was refused with "check the terms in x.d"; the cause is t (issue 34,
    item 8)."""
    model = Model("fading", coords=[x], T=(1 - t) * x.d**2 / 2)
    with pytest.raises(ModelError) as err:
        derive(model)
    text = str(err.value)
    assert "depends on t" in text and "t = " in text and "x.d" not in text, text
