"""A controller of the wrong arity or returning NaN is named in one line (issue 34, item 8)."""

import numba
import numpy as np
import pytest

import lagrange_gen as lg


@pytest.fixture(scope="module")
def cart_pole(generated):
    return generated("cart_pole")


@numba.njit
def _three_arguments(t, q, qd):
    return 0.0


@numba.njit
def _nan_at_start(t, q, qd, p):
    return np.nan


@numba.njit
def _nan_later(t, q, qd, p):
    return np.nan if t > 0.05 else 0.1


def test_controller_of_the_wrong_arity_is_one_line(cart_pole):
    with pytest.raises(lg.SimulationError) as err:
        lg.simulate(cart_pole, "rk4", q0=[0, 0.1], t_end=0.1, h=0.01, control=_three_arguments)
    text = str(err.value)
    assert "\n" not in text and "_three_arguments" in text and "(t, q, qd, p)" in text, text


@pytest.mark.parametrize("controller", [_nan_at_start, _nan_later])
def test_controller_returning_nan_is_named(cart_pole, controller):
    with pytest.raises(lg.SimulationError) as err:
        lg.simulate(cart_pole, "rk4", q0=[0, 0.1], t_end=0.1, h=0.01, control=controller)
    text = str(err.value)
    assert "\n" not in text and controller.__name__ in text and "input u" in text, text
