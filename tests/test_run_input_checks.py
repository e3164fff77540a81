"""simulate's inputs that used to pass unnoticed (issue 41): a q0 or v0 of more than one
dimension is refused (not flattened), a tolerance that controls nothing is refused (rtol >= 1,
which accepts every step as a run meaning fixed steps of dop853 asks for, says so in one line),
and a fixed-step run that will take more than a minute says how
long before it starts (one line on stderr; it is not refused)."""

import math
import re

import numpy as np
import pytest

from lagrange_gen import simulate
from lagrange_gen.errors import SimulationError
from lagrange_gen.run import checks as run_checks
from lagrange_gen.run import fixed_driver
from lagrange_gen.run.stepper import Stepper
from lagrange_gen.steppers.core import registry

Q0 = [0.1, 0.5]


@pytest.fixture(scope="module")
def cart(generated):
    return generated("cart_pendulum")


def _one_line(call):
    with pytest.raises(SimulationError) as info:
        call()
    message = str(info.value)
    assert "\n" not in message
    return message


@pytest.mark.parametrize("name", ["q0", "v0"])
@pytest.mark.parametrize("value", [[[0.1, 0.2]], np.array([[0.1], [0.2]]), np.zeros((2, 2))])
def test_a_state_of_more_than_one_dimension_is_refused(cart, name, value):
    given = {"q0": Q0, "v0": None, name: value}
    message = _one_line(lambda: simulate(cart, "rk4", given["q0"], given["v0"], t_end=0.01,
                                         h=1e-3))
    assert message.startswith(f"{name} must have shape (2,)")
    assert "x, theta" in message and str(np.shape(value)) in message


def test_the_step_api_refuses_it_the_same_way(cart):
    message = _one_line(lambda: Stepper(cart, "rk4", h=1e-3, q0=[[0.1, 0.2]]))
    assert "(2,)" in message and "x, theta" in message


@pytest.mark.parametrize("setting, value", [
    ("rtol", math.nan), ("rtol", math.inf), ("rtol", 0.0),
    ("rtol", -1e-6), ("atol", math.nan), ("atol", math.inf), ("atol", 0.0), ("atol", -1.0)])
@pytest.mark.parametrize("method", [m for m in registry.ADAPTIVE_METHODS
                                    if not registry.spec(m).contacts])
def test_a_tolerance_that_controls_nothing_is_refused(cart, method, setting, value):
    message = _one_line(lambda: simulate(cart, method, Q0, None, t_end=0.01, **{setting: value}))
    assert message.startswith(f"{setting} must be")


def test_tolerances_below_one_are_taken():
    spec = registry.spec("dop853")
    settings = run_checks.method_settings(spec, {"rtol": 0.5, "atol": 1e3})
    assert settings.rtol == 0.5 and settings.atol == 1e3


@pytest.mark.parametrize("rtol", [1.0, 1e3])
def test_rtol_of_one_or_more_says_it_controls_nothing(cart, rtol):
    with pytest.warns(RuntimeWarning, match=r"controls nothing.*every step is accepted") as caught:
        simulate(cart, "dop853", Q0, None, t_end=0.01, rtol=rtol)
    lines = [str(w.message) for w in caught if "controls nothing" in str(w.message)]
    assert len(lines) == 1 and "\n" not in lines[0]


@pytest.mark.parametrize("seconds, text", [
    (59.0, None), (61.0, "about 1 minute"), (200.0, "about 3.3 minutes"),
    (5 * 3600.0, "about 5 hours"), (3 * 86400.0, "about 3 days"),
    (2e3 * 86400 * 365.25, "about 2000 years")])
def test_the_long_run_line(seconds, text):
    line = run_checks.long_run_line("cart_pendulum", "rk4", 10**6, seconds / 10**6, 640)
    if text is None:
        assert line is None
        return
    assert "\n" not in line and text in line and "cart_pendulum, rk4" in line
    assert "1e+06 steps" in line and "640 steps" in line


def test_a_long_run_says_how_long_before_it_starts(cart, capsys, monkeypatch):
    """A cheap model whose measured step cost is replaced by 10 ms: 20000 steps, about 3.3
    minutes; the line comes before the run (the run itself takes a fraction of a second)."""
    order = []
    monkeypatch.setattr(fixed_driver, "seconds_per_step",
                        lambda *args: order.append("measured") or (0.01, 640))
    real = fixed_driver._chunks
    monkeypatch.setattr(fixed_driver, "_chunks",
                        lambda *args: order.append("ran") or real(*args))
    simulate(cart, "rk4", Q0, None, t_end=20.0, h=1e-3, jit="specialized")
    err = capsys.readouterr().err
    lines = [line for line in err.splitlines() if "will take" in line]
    assert len(lines) == 1 and "about 3.3 minutes" in lines[0] and "2e+04 steps" in lines[0]
    assert order == ["measured", "ran"]


def test_a_short_run_is_not_measured(cart, capsys, monkeypatch):
    monkeypatch.setattr(fixed_driver, "seconds_per_step",
                        lambda *args: pytest.fail("a short run was measured"))
    simulate(cart, "rk4", Q0, None, t_end=1.0, h=1e-3, jit="specialized")
    assert "will take" not in capsys.readouterr().err


def test_the_measurement_leaves_the_run_as_it_was(cart, capsys, monkeypatch):
    """The measured steps run on copies: the trajectory is the one of a run not measured."""
    measured = simulate(cart, "midpoint", Q0, None, t_end=12.0, h=1e-3, save_every=7,
                        jit="specialized")
    step, steps = fixed_driver.seconds_per_step(
        *_probe_arguments(cart))
    assert 0 < step < 1 and steps >= fixed_driver.PROBE_MIN_STEPS
    monkeypatch.setattr(fixed_driver, "ESTIMATE_AFTER_STEPS", 10**9)
    plain = simulate(cart, "midpoint", Q0, None, t_end=12.0, h=1e-3, save_every=7,
                     jit="specialized")
    np.testing.assert_array_equal(measured.q, plain.q)
    np.testing.assert_array_equal(measured.v, plain.v)
    assert "will take" not in capsys.readouterr().err


def _probe_arguments(cart):
    """seconds_per_step's arguments for the cart pendulum's midpoint glue at Q0."""
    from lagrange_gen.run.call_plan import method_plan
    from lagrange_gen.run.simulate import _Task
    plan = method_plan(cart, "midpoint")
    p = np.array(cart.DEFAULT_PARAMS, dtype=np.float64)
    task = _Task(cart, plan.spec, cart.run_midpoint, p, plan.default_settings, 1e-3, 0.0,
                 12_000, 7, jit="specialized", layout=plan.layout)
    q, v = np.array(Q0), np.zeros(2)
    out = fixed_driver.allocate(2, 2, plan.n_saved, np.zeros(plan.n_saved), 0)
    return task, cart.run_midpoint, q, v, out


def test_a_run_that_starts_interpreted_says_it_once_compiled(cart, capsys, monkeypatch):
    """An interpreted first run (jit/interpreted.py) measures nothing while Python steps; once
    it goes on compiled, the remaining steps are measured and announced."""
    from lagrange_gen.jit import first_run, portable
    monkeypatch.setattr(portable, "specialized_ready", lambda dispatcher, args: False)
    monkeypatch.setattr(portable, "portable_cached", lambda module, method: False)
    monkeypatch.setattr(fixed_driver, "_READY", {})
    monkeypatch.setattr(fixed_driver, "_INTERPRETED_S", {})
    monkeypatch.setattr(first_run, "expected_compile_seconds", lambda method: 0.0)
    monkeypatch.setenv(first_run.INTERPRETED_ENV, "1")
    remaining = []
    monkeypatch.setattr(fixed_driver, "seconds_per_step",
                        lambda task, run, q, v, out, steps, t: remaining.append((steps, t))
                        or (0.01, 64))
    traj = simulate(cart, "rk4", Q0, None, t_end=20.0, h=1e-3)
    first = fixed_driver.PROBE_STEPS
    assert traj.jit == f"interpreted, then portable from step {first}"
    assert remaining == [(20_000 - first, pytest.approx(first * 1e-3))]
    lines = [line for line in capsys.readouterr().err.splitlines() if "will take" in line]
    assert len(lines) == 1 and "about 3.3 minutes" in lines[0]
