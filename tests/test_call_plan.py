"""The warm path of simulate: what a (module, method) fixes is worked out once
(run/call_plan.py), refusals are never kept, and the shortcuts of a warm call (the plan's
parameters and settings, the vector check, the energy check's few rows) give what the general
path gives."""

import math
import warnings
import weakref
from fractions import Fraction

import numba
import numpy as np
import pytest

from lagrange_gen.errors import SimulationError
from lagrange_gen.run import call_plan, checks, consistent, control, energy_check
from lagrange_gen.run import simulate as simulate_module
from lagrange_gen.run.simulate import simulate

Q0, V0 = [0.1, 0.5], [0.0, 0.2]


@pytest.fixture(scope="module")
def cart(generated):
    return generated("cart_pendulum")


@pytest.fixture(scope="module")
def cart_pole(generated):
    return generated("cart_pole")


@pytest.fixture
def counted(monkeypatch):
    """{name: calls} of the checks a plan runs once, with no plan kept from another test."""
    monkeypatch.setattr(call_plan, "_PLANS", weakref.WeakKeyDictionary())
    counts = {"check_method": 0, "resolve_inputs": 0, "make_settings": 0}

    def counting(owner, name):
        original = getattr(owner, name)

        def wrapper(*args, **kwargs):
            counts[name] += 1
            return original(*args, **kwargs)
        monkeypatch.setattr(owner, name, wrapper)

    counting(consistent, "check_method")
    counting(control, "resolve_inputs")
    counting(call_plan, "make_settings")
    counting(checks, "make_settings")            # simulate's, through checks.method_settings
    return counts


def test_a_warm_call_does_not_run_the_plans_checks_again(cart, counted):
    first = simulate(cart, "midpoint", Q0, V0, t_end=0.01, h=1e-3)
    assert counted == {"check_method": 1, "resolve_inputs": 1, "make_settings": 1}
    for _ in range(3):
        again = simulate(cart, "midpoint", Q0, V0, t_end=0.01, h=1e-3)
    assert counted == {"check_method": 1, "resolve_inputs": 1, "make_settings": 1}
    np.testing.assert_array_equal(again.q, first.q)
    simulate(cart, "rk4", Q0, V0, t_end=0.01, h=1e-3)        # another method: its own plan
    assert counted == {"check_method": 2, "resolve_inputs": 2, "make_settings": 2}


def test_given_params_and_settings_take_the_general_path_every_call(cart, counted):
    for _ in range(2):
        simulate(cart, "midpoint", Q0, V0, t_end=0.01, h=1e-3, params={"g": 9.0},
                 newton_tol=1e-10)
    # the plan once (check_method, resolve_inputs and make_settings with no input), then each
    # call resolves its own params and settings
    assert counted == {"check_method": 1, "resolve_inputs": 3, "make_settings": 3}


def test_the_plans_parameters_and_settings_equal_the_general_paths(cart):
    plan = call_plan.method_plan(cart, "midpoint")
    p, hook, data = control.resolve_inputs(cart, None, None, 1e-3)
    assert hook is None and data is None
    np.testing.assert_array_equal(plan.default_params, p)
    assert not plan.default_params.flags.writeable          # the kept vector cannot change
    fresh = call_plan.run_params(plan, cart, None, None, None, 1e-3, 0.0, None, None)[0]
    assert fresh is not plan.default_params and fresh.flags.writeable
    assert plan.default_settings == checks.make_settings(plan.spec, {})
    by_plan = simulate(cart, "midpoint", Q0, V0, t_end=0.05, h=1e-3)
    general = simulate(cart, "midpoint", Q0, V0, t_end=0.05, h=1e-3, params={},
                       newton_tol=plan.default_settings.newton_tol)
    for name in ("t", "q", "v", "energy", "newton_iters"):
        np.testing.assert_array_equal(getattr(by_plan, name), getattr(general, name))
    assert by_plan.params == general.params and by_plan.settings == general.settings


def test_a_run_with_inputs_does_not_write_into_the_kept_parameters(cart_pole):
    plan = call_plan.method_plan(cart_pole, "midpoint")
    kept = plan.default_params.copy()

    @numba.njit
    def push(t, q, qd, p):
        return 3.0

    traj = simulate(cart_pole, "midpoint", [0.0, 0.2], [0.0, 0.0], t_end=0.01, h=1e-3,
                    control=push)
    assert np.all(traj.saved["input_u"] == 3.0)
    np.testing.assert_array_equal(plan.default_params, kept)


def test_a_refusal_is_not_kept_and_says_the_same_each_call(cart, counted):
    messages = []
    for _ in range(2):
        with pytest.raises(SimulationError) as info:
            simulate(cart, "rattle", Q0, V0, t_end=0.01, h=1e-3)
        messages.append(str(info.value))
    assert messages[0] == messages[1] and "rattle" in messages[0]
    assert counted["check_method"] == 2 and "rattle" not in call_plan._PLANS.get(cart, {})


def test_a_missing_parameter_is_refused_on_every_call(cart_pole, monkeypatch):
    monkeypatch.setattr(call_plan, "_PLANS", weakref.WeakKeyDictionary())
    monkeypatch.setattr(cart_pole, "DEFAULTS", cart_pole.DEFAULTS[:-1] + (None,))
    for _ in range(2):
        with pytest.raises(SimulationError, match="input u has no value"):
            simulate(cart_pole, "midpoint", [0.0, 0.2], [0.0, 0.0], t_end=0.01, h=1e-3)
    assert call_plan.method_plan(cart_pole, "midpoint").default_params is None


@pytest.mark.parametrize("value", [(0.1, 0.5), [1, 2], np.array([0.1, 0.5]),
                                   np.array([0.1, 9.0, 0.5])[::2]])
def test_vector_gives_a_fresh_contiguous_float64_copy(value):
    arr = checks.vector("q0", value, 2, ("x", "theta"))
    assert arr.dtype == np.float64 and arr.flags.c_contiguous and arr.flags.writeable
    assert arr.shape == (2,) and arr is not value
    np.testing.assert_array_equal(arr, np.asarray(value, dtype=float))


def test_vector_refuses_non_finite_entries_but_not_a_sum_that_overflows():
    with warnings.catch_warnings():
        warnings.simplefilter("error")                   # and says nothing about the overflow
        big = checks.vector("q0", [1e308, 1e308], 2, ("x", "theta"))      # the sum is inf
    np.testing.assert_array_equal(big, [1e308, 1e308])
    for bad in ([np.nan, 1.0], [np.inf, -np.inf], [1.0, -np.inf]):
        with warnings.catch_warnings(), \
                pytest.raises(SimulationError, match="q0 contains a non-finite value"):
            warnings.simplefilter("error")
            checks.vector("q0", bad, 2, ("x", "theta"))


@pytest.mark.parametrize("count", [1, 2, 16, 17, 18, 1001, 12345])
def test_spaced_rows_are_the_floors_of_even_spacing(count):
    most = 17
    rows = list(energy_check.spaced_rows(count, most))
    if count <= most:
        assert rows == list(range(count))
        return
    exact = [math.floor(Fraction(k * (count - 1), most - 1)) for k in range(most)]
    assert rows == exact and rows[0] == 0 and rows[-1] == count - 1
    assert len(set(rows)) == most


def test_energy_scale_equals_the_formula_over_its_rows(cart):
    traj = simulate(cart, "rk4", Q0, V0, t_end=1.0, h=1e-2)
    p = np.array(list(traj.params.values()))
    for most in (5, 17, 1001):
        rows = list(energy_check.spaced_rows(len(traj.t), most))
        V = np.array([cart.energy(traj.q[k], np.zeros(2), traj.t[k], p) for k in rows])
        T = traj.energy[rows] - V
        expected = T.max() + V.max() - V.min()
        assert energy_check.energy_scale(cart, traj.q, traj.t, traj.energy, p, most) == \
            pytest.approx(expected, rel=1e-15, abs=0)
