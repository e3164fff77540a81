"""How coordinates(), parameters() and inputs() read their names and defaults: sympy's
``symbols`` habits (a trailing comma gives a tuple) and one scalar default for every name."""

import pytest

from lagrange_gen import ModelError
from lagrange_gen.model.model import inputs
from lagrange_gen.model.symbols import Coordinate, coordinates, parameters


def test_a_trailing_comma_gives_a_tuple_as_sympy_symbols_does():
    s, = coordinates("s,")
    assert isinstance(s, Coordinate) and s.name == "s"
    pair = coordinates("x, y,")
    assert isinstance(pair, tuple) and [c.name for c in pair] == ["x", "y"]
    k, = parameters("k,", defaults=2.0)
    assert k.default == 2.0
    u, = inputs("u,")
    assert u.default is None


def test_without_a_comma_one_name_is_the_symbol_and_several_a_list():
    assert isinstance(coordinates("x"), Coordinate)
    assert [c.name for c in coordinates("x y")] == ["x", "y"]


def test_a_scalar_default_applies_to_every_name():
    taus = inputs("tau1 tau2 tau3", defaults=0.0)
    assert [u.default for u in taus] == [0.0, 0.0, 0.0]
    ms = parameters("m1 m2", defaults=1.5)
    assert [m.default for m in ms] == [1.5, 1.5]


def test_messages_name_the_function_called():
    with pytest.raises(ModelError, match=r"^inputs\('u1 u2'\): 2 names but 3 defaults"):
        inputs("u1 u2", defaults=(0.0, 0.0, 0.0))
    with pytest.raises(ModelError, match=r"^parameters\('a b'\): 2 names but 1 defaults"):
        parameters("a b", defaults=[1.0])
    with pytest.raises(ModelError, match=r"^inputs\('u1 u2'\): defaults given for w"):
        inputs("u1 u2", defaults={"w": 1.0})
    with pytest.raises(ModelError, match=r"^input u: default 'x' is not a finite number"):
        inputs("u", defaults="x")
    with pytest.raises(ModelError, match=r"^coordinates\('1x'\): coordinate name '1x' is not a "
                                         r"valid Python identifier"):
        coordinates("1x")
