"""Non-finite arithmetic inside the jitted kernels and steppers (issue 11): V = log(x) at x = 0
divides by zero. With numpy's error model in every njit decorator this gives inf/NaN, which the
run loop reports as NON_FINITE; simulate raises BlowUp naming the step, the time and the state,
never a ZeroDivisionError from inside numba. A singular Newton matrix on a regular H is named as
such (SINGULAR_NEWTON), not as a singular mass matrix (issue 11)."""

import math

import numpy as np
import pytest

from lagrange_gen.cli.main import main
from lagrange_gen.codegen import generate_model
from lagrange_gen.errors import BlowUp, NewtonDivergence, SingularMass
from lagrange_gen.run.loader import import_generated
from lagrange_gen.run.simulate import simulate

from stepper_util import HERE, model  # noqa: F401  (model is a fixture)


@pytest.fixture(scope="module")
def singular(tmp_path_factory):
    """name -> generated module (rk4 and midpoint only: little to compile)."""
    out = tmp_path_factory.mktemp("nonfinite")
    return {name: import_generated(generate_model(HERE / "models" / f"{name}.py", out,
                                                  methods=["rk4", "midpoint"]).path)
            for name in ("log_potential", "sqrt_potential")}


def test_compiled_kernel_divides_by_zero_like_numpy(singular):
    """The generated force kernel at x = 0 returns -inf like its Python body on numpy scalars,
    instead of raising ZeroDivisionError."""
    mod = singular["log_potential"]
    q, qd, p = np.zeros(1), np.zeros(1), np.array([1.0, 1.0])
    out, ref = np.empty(1), np.empty(1)
    mod.rhs(q, qd, 0.0, p, out)
    with np.errstate(divide="ignore"):
        mod.rhs.py_func(q, qd, 0.0, p, ref)
    assert out[0] == ref[0] == -math.inf


@pytest.mark.parametrize("method", ["rk4", "midpoint"])
def test_log_potential_started_at_its_singularity(singular, method):
    with pytest.raises(BlowUp) as info:
        simulate(singular["log_potential"], method, [0.0], [0.0], t_end=1.0, h=0.01)
    msg = str(info.value)
    assert "the initial state (t = 0" in msg
    assert "energy became non-finite (E = -inf) at x=0, x_dot=0" in msg
    assert info.value.step == 0 and "\n" not in msg


def test_log_potential_falling_through_zero_names_the_step(singular):
    """From x = 1 at rest, v^2 / 2 + log(x) = 0: the particle reaches x = 0 at
    t = int_0^1 dx / sqrt(-2 log x) = sqrt(pi / 2). rk4 steps over it to x < 0, where log(x) is
    NaN: BlowUp at that step, with its time."""
    with pytest.raises(BlowUp) as info:
        simulate(singular["log_potential"], "rk4", [1.0], [0.0], t_end=5.0, h=0.01)
    exc = info.value
    assert abs(exc.time - math.sqrt(math.pi / 2)) < 0.03 and exc.step == round(exc.time / 0.01)
    assert f"step {exc.step} of 500 (t = {exc.time:.9g}" in str(exc)
    assert "energy became non-finite (E = nan)" in str(exc) and exc.state[0] < 0


def test_infinite_newton_matrix_is_non_finite_not_singular(singular):
    """V = sqrt(x) at x = 0: E = 0, but the midpoint Newton matrix holds d2V/dx2 = -inf."""
    with pytest.raises(BlowUp) as info:
        simulate(singular["sqrt_potential"], "midpoint", [0.0], [0.0], t_end=1.0, h=0.01)
    msg = str(info.value)
    assert "step 1 of 100" in msg and "non-finite value" in msg and "from x=0, x_dot=0" in msg
    assert "singular" not in msg


def test_cli_reports_the_blow_up_in_one_line(singular, capsys):
    code = main(["simulate", singular["log_potential"].__file__, "--method", "rk4", "--h", "0.01",
                 "--t-end", "1", "--q0", "0"])
    err = capsys.readouterr().err
    assert code != 0 and "Traceback" not in err and len(err.strip().splitlines()) == 1
    assert "initial state" in err and "x=0" in err


def test_singular_newton_matrix_with_a_regular_mass_matrix(model):
    """Oscillator m x'' = -k x with k = -1 (unstable): implicit Euler's Newton matrix is
    m + h^2 k = 0 at h = 1 while H = m = 1 is regular."""
    with pytest.raises(NewtonDivergence) as info:
        simulate(model("oscillator"), "implicit_euler", [1.0], [0.0], t_end=2.0, h=1.0,
                 params={"k": -1.0})
    msg = str(info.value)
    assert not isinstance(info.value, SingularMass)
    assert "step 1 of 2" in msg and "singular Newton matrix" in msg and "mass matrix" not in msg



@pytest.mark.parametrize("bound", [1e150, math.inf])
def test_check_state_sorts_every_entry_and_bound(bound):
    """base.check_state, run after every step: NaN and +-inf in any entry of q or v are
    NON_FINITE, also under an infinite blow-up bound (its fast path compares |x| <= bound, which
    inf passes when bound is inf); a finite entry past a finite bound is UNSTABLE."""
    from lagrange_gen.steppers.core.state_checks import check_state
    from lagrange_gen.steppers.core.status import NON_FINITE, OK, UNSTABLE
    for bad, expected in ((math.nan, NON_FINITE), (math.inf, NON_FINITE),
                          (-math.inf, NON_FINITE),
                          (1e200, UNSTABLE if bound < math.inf else OK)):
        for which in range(4):
            state = np.array([0.5, -2.0, 1.0, 3.0])
            state[which] = bad
            assert check_state(state[:2], state[2:], bound) == expected, (bad, which)
    assert check_state(np.array([0.5, -2.0]), np.array([1.0, 3.0]), bound) == OK
