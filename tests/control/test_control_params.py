"""Controllers inside the loop: the energy balance of a controlled run closes at the method's
order, and new gains passed as control_params run the loop already compiled."""

import numba
import numpy as np
import pytest

import lagrange_gen as lg
from control_util import torque_pendulum  # noqa: F401  (a fixture)
from lagrange_gen.jit import compile_notice
from lagrange_gen.run.control import controlled_run, make_apply

Q0, V0, T_END = [0.2, 0.6], [0.0, -0.4], 2.0


@numba.njit
def damp_and_drive(t, q, qd, p, c):
    return -c[0] * qd[1] + c[1] * np.sin(3.0 * t)


def fit(steps, errors):
    return float(np.polyfit(np.log(1.0 / np.asarray(steps)), np.log(errors), 1)[0])


def test_balance_with_a_controller_closes_at_the_method_order(torque_pendulum):
    """midpoint (order 2) with u = -0.8 theta_dot + sin(3 t), held over each step: the work W
    of the held input closes E - E0 - W at order 2, as without a controller."""
    steps = (32, 64, 128, 256)
    errors = []
    for n in steps:
        tr = lg.simulate(torque_pendulum, "midpoint", Q0, V0, t_end=T_END, h=T_END / n,
                         control=damp_and_drive, control_params=[0.8, 1.0])
        errors.append(np.abs(tr.energy_balance).max())
    assert tr.max_energy_error > 0.1            # the controller does work
    slope = fit(steps, errors)
    assert abs(slope - 2) < 0.3, (slope, errors)


@pytest.mark.parametrize("jit", ["specialized", "portable"])
def test_new_gains_run_the_compiled_loop(torque_pendulum, jit):
    """Three gain vectors, one compile: the loop (the specialized one of model, method and
    controller, or the portable controlled glue) is compiled by the first run only, and each
    run applies its own gains (the saved input is the controller's value at each saved
    state), also when the loop's choice was made by an earlier run."""
    run = controlled_run(torque_pendulum, "midpoint", make_apply(damp_and_drive, True))
    loops = len(run.overloads)
    before = None
    for gains in ([0.5, 0.0], [2.0, 0.3], [0.0, -1.0]):
        tr = lg.simulate(torque_pendulum, "midpoint", Q0, V0, t_end=0.2, h=0.01,
                         control=damp_and_drive, control_params=gains, jit=jit)
        assert tr.jit == jit
        expected = -gains[0] * tr.v[:, 1] + gains[1] * np.sin(3.0 * tr.t)
        np.testing.assert_allclose(tr.saved["input_u"][:, 0], expected, rtol=1e-14, atol=1e-15)
        if before is not None:            # the runs after the first compile nothing
            assert compile_notice.compiles() == before, gains
        before = compile_notice.compiles()
    assert len(run.overloads) == (1 if jit == "specialized" else loops)


def test_control_params_refusals(torque_pendulum):
    def one_line(**kwargs):
        with pytest.raises(lg.SimulationError) as err:
            lg.simulate(torque_pendulum, "midpoint", Q0, V0, t_end=0.1, h=0.01, **kwargs)
        assert "\n" not in str(err.value)
        return str(err.value)

    assert "control= is no controller" in one_line(control_params=[1.0])
    assert "control_params[1] = nan is not finite" in one_line(
        control=damp_and_drive, control_params=[1.0, float("nan")])
    assert "flat sequence" in one_line(control=damp_and_drive, control_params=[[1.0, 2.0]])

    @numba.njit
    def four(t, q, qd, p):
        return 0.0

    assert "must take (t, q, qd, p, c)" in one_line(control=four, control_params=[1.0])
    assert "must take (t, q, qd, p)" in one_line(control=damp_and_drive)


def test_stepper_says_when_it_compiles(torque_pendulum, monkeypatch, capsys):
    """The Stepper's constructor and first step compile its loop (seconds): one notice line
    each when numba compiles there; a warm step prints nothing and compiles nothing."""
    monkeypatch.setattr(compile_notice, "NOTICE_AFTER_S", 0.0)
    before = compile_notice.compiles()
    stepper = lg.Stepper(torque_pendulum, "rk4", h=0.01, q0=Q0)
    stepper.step(0.1)
    lines = capsys.readouterr().err.splitlines()
    compiled = compile_notice.compiles() > before
    assert (1 <= len(lines) <= 2) if compiled else not lines, lines
    assert all(line.startswith("lagrange-gen: compiling Stepper(rk4) for torque_pendulum "
                               "(first use) ... done in") for line in lines)
    before = compile_notice.compiles()
    stepper.step(0.2)
    assert compile_notice.compiles() == before
    assert capsys.readouterr().err == ""
