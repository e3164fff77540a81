"""Every public entry checks shapes and dtypes before compiled code runs (issue 34, item 1):
a wrong shape is one SimulationError line naming the argument, never a read or write past an
array inside a kernel or a stepper."""

import numpy as np
import pytest

import lagrange_gen as lg


@pytest.fixture(scope="module")
def double_pendulum(generated):
    return generated("double_pendulum")


def _one_line(err, *words):
    text = str(err.value)
    assert "\n" not in text, text
    for word in words:
        assert word in text, text


@pytest.mark.parametrize("q0", [[0.1], [0.1, 0.2, 0.3, 0.4], [[0.1, 0.2], [0.3, 0.4]], [0.1, np.nan]])
def test_stepper_refuses_a_q0_of_the_wrong_shape(double_pendulum, q0):
    with pytest.raises(lg.SimulationError) as err:
        lg.Stepper(double_pendulum, "rk4", h=0.01, q0=q0)
    _one_line(err, "q0")


def test_stepper_refuses_a_v0_of_the_wrong_shape(double_pendulum):
    with pytest.raises(lg.SimulationError) as err:
        lg.Stepper(double_pendulum, "rk4", h=0.01, v0=[1.0])
    _one_line(err, "v0", "th1, th2")


@pytest.mark.parametrize("h, t0", [(np.inf, 0.0), (0.01, np.nan), (0.01, "a")])
def test_stepper_refuses_non_finite_times(double_pendulum, h, t0):
    with pytest.raises(lg.SimulationError) as err:
        lg.Stepper(double_pendulum, "rk4", h=h, t0=t0)
    _one_line(err)


def test_stepper_with_the_right_shapes_still_runs(double_pendulum):
    stepper = lg.Stepper(double_pendulum, "rk4", h=0.01, q0=(0.1, 0.2))
    stepper.step(k=3)
    assert stepper.steps == 3 and stepper.q.shape == (2,)


@pytest.mark.parametrize("args, name", [
    (lambda q, p: (q[:1], q, 0.0, p), "q"),
    (lambda q, p: (q, np.zeros(3), 0.0, p), "qd"),
    (lambda q, p: (q, q, 0.0, p[:2]), "p"),
    (lambda q, p: (q, q, 0.0, np.zeros(5, dtype=np.int64)), "p"),
    (lambda q, p: (q, q, "t", p), "t"),
])
def test_kernel_called_from_python_checks_its_arguments(double_pendulum, args, name):
    q, p = np.zeros(2), double_pendulum.DEFAULT_PARAMS.copy()
    with pytest.raises(lg.SimulationError) as err:
        double_pendulum.energy(*args(q, p))
    _one_line(err, "energy", repr(name))


def test_kernel_output_of_the_wrong_shape_is_refused_before_it_is_written(double_pendulum):
    q, p = np.zeros(2), double_pendulum.DEFAULT_PARAMS.copy()
    H = np.full((1, 1), 7.0)
    with pytest.raises(lg.SimulationError) as err:
        double_pendulum.mass_matrix(q, 0.0, p, H)
    _one_line(err, "mass_matrix", "'H'", "(2, 2)")
    assert H[0, 0] == 7.0


def test_kernel_with_the_right_arguments_still_answers(double_pendulum):
    q, p = np.array([0.1, 0.2]), double_pendulum.DEFAULT_PARAMS.copy()
    H = np.empty((2, 2))
    double_pendulum.mass_matrix(q, 0.0, p, H)
    assert H[0, 0] == pytest.approx(2.0)
    assert np.isfinite(double_pendulum.energy(q, q, 0.0, p))


def test_step_jacobian_and_linearize_refuse_wrong_shapes(double_pendulum):
    with pytest.raises(lg.SimulationError) as err:
        lg.step_jacobian(double_pendulum, "rk4", 0.01, [0.1], [0.0, 0.0])
    _one_line(err, "q")
    with pytest.raises(lg.SimulationError) as err:
        lg.linearize(double_pendulum, [0.0, 0.0], qd=[0.0, 0.0, 0.0])
    _one_line(err, "qd")


def test_ensemble_refuses_q0_of_the_wrong_shape(double_pendulum):
    with pytest.raises(lg.SimulationError) as err:
        lg.ensemble(double_pendulum, "rk4", q0=np.zeros((4, 3)), t_end=0.1, h=0.01)
    _one_line(err, "q0")


# Issue 34, item 8: the step API's other inputs ---------------------------------------------------

@pytest.mark.parametrize("k", [-3, 0, 2.5, "2", True])
def test_stepper_step_count_must_be_a_positive_integer(double_pendulum, k):
    stepper = lg.Stepper(double_pendulum, "rk4", h=0.01, q0=[0.1, 0.2])
    with pytest.raises(lg.SimulationError) as err:
        stepper.step(k=k)
    _one_line(err, "k")
    assert stepper.steps == 0


def test_stepper_unknown_method_is_one_line(double_pendulum):
    with pytest.raises(lg.SimulationError) as err:
        lg.Stepper(double_pendulum, "rk5", h=0.01)
    _one_line(err, "rk5", "rk4")


def test_stepper_refuses_to_step_on_after_a_failure(double_pendulum):
    stepper = lg.Stepper(double_pendulum, "explicit_euler", h=0.5, q0=[2.0, 3.0], v0=[5.0, -5.0],
                         blowup_bound=10.0)
    with pytest.raises(lg.BlowUp):
        stepper.step(k=100)
    steps = stepper.steps
    with pytest.raises(lg.SimulationError) as err:
        stepper.step()
    _one_line(err, "failed")
    assert stepper.steps == steps
