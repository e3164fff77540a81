"""Inputs inside the loop (controller, Signal, constants), saved outputs, the Stepper API."""

import numba
import numpy as np
import pytest

import lagrange_gen as lg
from control_util import torque_pendulum  # noqa: F401  (a fixture)
from lagrange_gen.model.model import Model, coordinates, parameters
from lagrange_gen.run.control import Signal


@pytest.fixture(scope="module")
def cart_pole(generated):
    return generated("cart_pole")


def test_input_without_value_is_one_line_naming_it(torque_pendulum):
    with pytest.raises(lg.SimulationError) as err:
        lg.simulate(torque_pendulum, "rk4", q0=[0, 0.1], t_end=0.1, h=0.01)
    assert "input u has no value" in str(err.value) and "\n" not in str(err.value)


def test_input_must_be_declared_by_inputs():
    x = coordinates("x")
    k = parameters("k", defaults=1.0)
    with pytest.raises(lg.ModelError, match="input 2 is not declared by lagrange_gen.inputs"):
        Model("bad", coords=[x], T=x.d**2 / 2, V=k * x**2 / 2, inputs=[2])


def test_inputs_are_the_trailing_parameters(cart_pole):
    assert cart_pole.PARAMS[-1] == "u" and cart_pole.INPUTS == ("u",)
    assert cart_pole.OUTPUTS == ("cart", "tip_x")


@pytest.mark.parametrize("method", ["midpoint", "rk4"])
def test_constant_signal_equals_constant_parameter(cart_pole, method):
    """The hook writes the same slot the parameter occupies: bitwise the same run."""
    ref = lg.simulate(cart_pole, method, q0=[0, 0.1], t_end=1.0, h=0.01, params={"u": 0.4})
    sig = lg.simulate(cart_pole, method, q0=[0, 0.1], t_end=1.0, h=0.01,
                      control=Signal([0.0, 5.0], [0.4, 0.4]))
    np.testing.assert_array_equal(ref.q, sig.q)
    np.testing.assert_array_equal(sig.saved["input_u"][:, 0], 0.4)
    l = 0.5
    np.testing.assert_allclose(ref.saved["output_tip_x"][:, 0], ref.q[:, 0] + l * np.sin(ref.q[:, 1]),
                               rtol=1e-15)


def test_signal_holds(cart_pole):
    """Zero-order hold: the last sample at the step's start; linear: interpolated at the middle
    of the step (saved: the value held over the step starting at each row)."""
    times, values, h = np.array([0.0, 0.3, 0.7]), np.array([1.0, -2.0, 0.5]), 0.01
    zoh = lg.simulate(cart_pole, "rk4", q0=[0, 0.1], t_end=1.0, h=h, control=Signal(times, values))
    i = np.searchsorted(times, zoh.t + 1e-12, side="right") - 1
    np.testing.assert_array_equal(zoh.saved["input_u"][:, 0], values[i])
    lin = lg.simulate(cart_pole, "rk4", q0=[0, 0.1], t_end=1.0, h=h,
                      control=Signal(times, values, hold="linear"))
    np.testing.assert_allclose(lin.saved["input_u"][:, 0], np.interp(lin.t + h / 2, times, values),
                               atol=1e-13)


def test_controller_sees_the_state_at_each_step_start(cart_pole):
    """A controller u = -k theta_dot inside the loop equals a step-by-step Python loop with
    the Stepper API (same method, same zero-order hold), bitwise."""
    @numba.njit
    def damp(t, q, qd, p):
        return -2.0 * qd[1] + 0.1 * t

    traj = lg.simulate(cart_pole, "midpoint", q0=[0, 0.2], t_end=0.5, h=0.01, control=damp)
    stepper = lg.Stepper(cart_pole, "midpoint", h=0.01, q0=[0, 0.2])
    for row in range(1, len(traj.t)):
        stepper.step(-2.0 * stepper.v[1] + 0.1 * stepper.t)
        np.testing.assert_array_equal(stepper.q, traj.q[row])
        np.testing.assert_array_equal(stepper.v, traj.v[row])
    assert stepper.steps == 50 and stepper.t == pytest.approx(0.5, abs=1e-15)


def test_stepper_k_steps_equals_simulate(cart_pole):
    ref = lg.simulate(cart_pole, "implicit_euler", q0=[0.1, 0.3], v0=[0, -1], t_end=0.2, h=1e-3,
                      params={"u": -0.7})
    stepper = lg.Stepper(cart_pole, "implicit_euler", h=1e-3, q0=[0.1, 0.3], v0=[0, -1])
    stepper.step([-0.7], k=150)
    stepper.step(-0.7, k=50)
    np.testing.assert_array_equal(stepper.state, np.concatenate((ref.q[-1], ref.v[-1])))


def test_stepper_refusals(cart_pole, generated):
    with pytest.raises(lg.SimulationError, match="u has 2 entries for 1 input"):
        lg.Stepper(cart_pole, "rk4", h=0.01).step([1.0, 2.0])
    with pytest.raises(lg.SimulationError, match="without constraints"):
        lg.Stepper(generated("cartesian_pendulum"), "rattle", h=0.01)
    with pytest.raises(lg.BlowUp):
        lg.Stepper(cart_pole, "explicit_euler", h=0.5, q0=[0, 3.0], blowup_bound=10.0).step(0.0, k=100)


def test_frozen_input_is_a_constant(gen_dir):
    """--freeze u=0.4: u leaves PARAMS and INPUTS and the run equals params={"u": 0.4}."""
    from pathlib import Path

    from lagrange_gen.codegen import generate_model
    from lagrange_gen.run.loader import import_generated
    root = Path(__file__).resolve().parents[2]
    out = gen_dir / "frozen_u"
    mod = import_generated(generate_model(root / "models" / "cart_pole.py", out, methods=["rk4"],
                                          freeze={"u": 0.4}).path)
    assert mod.INPUTS == () and "u" not in mod.PARAMS and mod.OUTPUTS == ("cart", "tip_x")
    with pytest.warns(UserWarning, match=r"^cart_pole has no inputs, .*; frozen in this "
                                         r"module, so constants: u$"):
        A, B, C, D = lg.linearize(mod, [0, 0], [0, 0])
    assert B.shape == (4, 0) and C.shape == (2, 4)
    H, rhs = np.zeros((2, 2)), np.zeros(2)
    mod.dynamics(np.zeros(2), np.zeros(2), 0.0, mod.DEFAULT_PARAMS, H, rhs)
    assert rhs[0] == 0.4


@pytest.mark.parametrize("method", ["verlet", "midpoint", "symplectic_euler"])
def test_input_change_restarts_cached_state(gen_dir, method):
    """Zero-order hold means each step is the method's step with that step's input: a run
    whose input switches at t = 0.5 equals two runs with constant inputs, the second started
    from the end of the first. verlet's explicit path caches the acceleration between steps;
    a switched input must not leave the stale one in use."""
    from pathlib import Path

    from lagrange_gen.codegen import generate_model
    from lagrange_gen.run.loader import import_generated
    mod = import_generated(generate_model(Path(__file__).resolve().parent / "forced_oscillator.py",
                                          gen_dir).path)
    assert mod.MASS_IS_CONSTANT and mod.FORCES_VELOCITY_FREE
    switched = lg.simulate(mod, method, q0=[0.3], t_end=1.0, h=0.01,
                           control=Signal([0.0, 0.5], [0.0, 1.0]))
    first = lg.simulate(mod, method, q0=[0.3], t_end=0.5, h=0.01, params={"u": 0.0})
    second = lg.simulate(mod, method, q0=first.q[-1], v0=first.v[-1], t0=0.5, t_end=1.0, h=0.01,
                         params={"u": 1.0})
    np.testing.assert_array_equal(switched.q[:51], first.q)
    np.testing.assert_allclose(switched.q[50:], second.q, rtol=1e-14, atol=1e-15)
    np.testing.assert_allclose(switched.v[50:], second.v, rtol=1e-14, atol=1e-15)
    stepper = lg.Stepper(mod, method, h=0.01, q0=[0.3])
    stepper.step(0.0, k=50)
    stepper.step(1.0, k=50)
    np.testing.assert_allclose(stepper.state, [second.q[-1, 0], second.v[-1, 0]], rtol=1e-14)


def test_controller_of_wrong_size_is_refused(cart_pole):
    @numba.njit
    def two(t, q, qd, p):
        return np.array([1.0, 2.0])

    with pytest.raises(lg.SimulationError, match="controller two returns 2 value.s. at t0 for 1 input"):
        lg.simulate(cart_pole, "rk4", q0=[0, 0.1], t_end=0.1, h=0.01, control=two)
