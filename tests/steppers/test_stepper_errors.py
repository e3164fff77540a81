"""Failures come back as exceptions that name the step, the time, the state (and the Newton
residual); bad inputs are one-line errors."""

import math
import re
import shlex

import numpy as np
import pytest

from lagrange_gen.cli.main import main
from lagrange_gen.codegen import generate_model
from lagrange_gen.errors import BlowUp, NewtonDivergence, SimulationError, SingularMass
from lagrange_gen.run.loader import import_generated
from lagrange_gen.run.simulate import simulate

from stepper_util import MODEL_FILES, model  # model is a fixture


def test_newton_divergence_names_the_failing_step(model):
    """Midpoint with at most 2 Newton iterations and a tight tolerance: fine while the pendulum
    falls slowly from near the top, fails once it is fast. The exception must point at the step
    that failed and carry the state that step started from."""
    mod = model("pendulum")
    h, newton = 0.1, dict(max_iter=2, newton_tol=1e-14)
    with pytest.raises(NewtonDivergence) as info:
        simulate(mod, "midpoint", [3.1], [0.0], t_end=20, h=h, **newton)
    exc = info.value
    k = exc.step
    assert k > 10
    msg = str(exc)
    assert f"step {k} of 200" in msg and "residual" in msg and "theta=" in msg
    assert exc.time == pytest.approx((k - 1) * h)
    assert math.isfinite(exc.residual) and exc.residual > 0
    # the k-1 steps before it succeed, and end in the state the exception reports
    before = simulate(mod, "midpoint", [3.1], [0.0], t_end=(k - 1) * h, h=h, **newton)
    assert before.n_steps == k - 1
    np.testing.assert_allclose(exc.state, np.concatenate([before.q[-1], before.v[-1]]),
                               rtol=1e-12, atol=1e-12)


def test_huge_step_with_few_iterations_fails_at_step_one(model):
    with pytest.raises(NewtonDivergence, match=r"step 1 of .*Newton did not converge in 2"):
        simulate(model("cart_pendulum"), "midpoint", [0.1, 0.5], [0, 0], t_end=10, h=5.0,
                 max_iter=2)


def test_unstable_explicit_euler_reports_first_step_past_the_bound(model):
    mod = model("oscillator")
    omega, h, bound = 3.0, 0.5 / 3.0, 1e3          # tau = 0.5: growth sqrt(1.25) per step
    A = np.array([[1.0, h], [-omega**2 * h, 1.0]])
    z, expected = np.array([1.0, 0.0]), 0
    while np.abs(z).max() <= bound:
        z, expected = A @ z, expected + 1
    with pytest.raises(BlowUp) as info:
        simulate(mod, "explicit_euler", [1.0], [0.0], t_end=100, h=h,
                 params={"k": omega**2}, blowup_bound=bound)
    assert info.value.step == expected
    assert f"step {expected} of" in str(info.value) and "blow-up bound" in str(info.value)


def test_overflow_is_reported_as_non_finite(model):
    with pytest.raises(BlowUp, match="non-finite"):
        simulate(model("oscillator"), "explicit_euler", [1.0], [0.0], t_end=1e4, h=10.0,
                 params={"k": 1.0}, blowup_bound=math.inf)


def test_singular_mass_matrix_is_an_error_not_nan(model):
    with pytest.raises(SingularMass, match=r"step 1 of .*singular mass matrix H\(q\) at q1=0"):
        simulate(model("spherical"), "rk4", [0.0, 0.0], [0.1, 0.2], t_end=1, h=1e-2)


@pytest.mark.parametrize("kwargs, match", [
    (dict(q0=[0.1]), "q0 has 1 entries but the model has 2 coordinates"),
    (dict(v0=[0.0, 0.0, 0.0]), "v0 has 3 entries"),
    (dict(q0=[math.nan, 0.0]), "q0 contains a non-finite value"),
    (dict(v0=[math.inf, 0.0]), "v0 contains a non-finite value"),
    (dict(h=0.0), "h must be > 0"),
    (dict(h=-1e-3), "h must be > 0"),
    (dict(h=math.nan), "h must be a finite number"),
    (dict(t_end=-1.0), "t_end = -1.0 is before t0"),
    (dict(save_every=0), "save_every must be a positive integer"),
    (dict(method="implicit_euler", max_iter=0), "max_iter must be a positive integer"),
    (dict(max_iter=3), "method 'rk4' has no setting 'max_iter'"),
    (dict(params={"nope": 1.0}), "unknown parameter 'nope'"),
    (dict(method="leapfrog"), "unknown method 'leapfrog'"),
])
def test_bad_input_is_a_one_line_error(model, kwargs, match):
    args = dict(method="rk4", q0=[0.1, 0.5], v0=[0.0, 0.0], t_end=1.0, h=1e-3)
    args.update(kwargs)
    with pytest.raises(SimulationError, match=match) as info:
        simulate(model("cart_pendulum"), **args)
    assert "\n" not in str(info.value)


def test_missing_required_parameter_is_named(model):
    with pytest.raises(SimulationError, match=r"parameter\(s\) k have no value"):
        simulate(model("oscillator"), "rk4", [1.0], [0.0], t_end=1.0, h=1e-2)


def test_method_not_generated_says_which_command_to_run(tmp_path, monkeypatch):
    """The hint names the module's own directory (-o) and options; following it regenerates
    that very file with the method added (it used to drop -o and write generated/ instead)."""
    out = tmp_path / "gen dir"
    result = generate_model(MODEL_FILES["pendulum"], out, methods=["rk4"])
    mod = import_generated(result.path)
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SimulationError, match=r"without method 'midpoint'") as info:
        simulate(mod, "midpoint", [0.1], [0.0], t_end=1.0, h=1e-2)
    command = re.search(r"run `([^`]*)`", str(info.value)).group(1)
    argv = shlex.split(command)
    assert argv[0] == "lagrange-gen" and argv[argv.index("-o") + 1] == "gen dir"
    assert argv[argv.index("--methods") + 1] == "midpoint,rk4"
    assert main(argv[1:]) == 0
    text = result.path.read_text()
    assert "METHODS = ('midpoint', 'rk4')" in text
    assert not (tmp_path / "generated").exists()
