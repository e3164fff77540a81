"""simulate's checks before and after a run (issues 10 and 11), exercised as a user would: the
public API lagrange_gen.simulate and `lagrange-gen simulate` through cli.main. Every refusal is
one line naming the argument, parameter or element, with a non-zero exit and no traceback."""

import math
import re
import warnings
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest
import scipy.linalg

from lagrange_gen import simulate
from lagrange_gen.cli.main import main
from lagrange_gen.codegen import generate_model
from lagrange_gen.errors import EnergyWarning, SimulationError
from lagrange_gen.run import checks as run_checks
from lagrange_gen.run.energy_check import ENERGY_FRACTION, is_conservative
from lagrange_gen.run.loader import import_generated

MODELS = Path(__file__).resolve().parent.parent / "models"
Q0, V0 = [0.1, 0.5], [0.0, 0.0]


@pytest.fixture(scope="module")
def cart(generated):
    return generated("cart_pendulum")


@pytest.fixture(scope="module")
def prandtl(generated):
    return generated("prandtl")


def cli(capsys, *argv):
    """(exit code, stdout, stderr) of `lagrange-gen simulate ARGV`."""
    code = main(["simulate", *map(str, argv)])
    out, err = capsys.readouterr()
    return code, out, err


def assert_one_line_error(code, err, *fragments):
    assert code != 0 and "Traceback" not in err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("lagrange-gen: error:"), err
    for fragment in fragments:
        assert fragment in lines[0], (fragment, lines[0])


# Issue 10, item 4: element coefficients at run time --------------------------------------------

@pytest.mark.parametrize("params, coefficient, source", [
    ({"eta": -1.0}, "threshold = -1", "eta = -1"),
    ({"eta": 0.0}, "threshold = 0", "eta = 0"),
    ({"k1": -5.0}, "stiffness = -5", "k1 = -5"),
])
def test_nonpositive_element_coefficient_is_refused(prandtl, params, coefficient, source):
    with pytest.raises(SimulationError) as info:
        simulate(prandtl, "implicit_euler", [0.0], [0.0], t_end=1.0, h=0.01, params=params)
    msg = str(info.value)
    assert "element 'slider'" in msg and coefficient in msg and source in msg and "\n" not in msg


def test_nonpositive_element_coefficient_on_the_command_line(prandtl, capsys):
    code, out, err = cli(capsys, prandtl.__file__, "--method", "implicit_euler", "--h", 0.01,
                         "--t-end", 1, "--param", "eta=-1")
    assert_one_line_error(code, err, "element 'slider'", "threshold = -1", "eta = -1")
    assert "steps to t" not in out        # refused before the run


def test_frozen_nonpositive_threshold_is_refused(tmp_path):
    frozen = generate_model(MODELS / "prandtl.py", tmp_path, methods=["nonsmooth_euler"],
                            freeze={"eta": 0.0})
    with pytest.raises(SimulationError, match=r"threshold = 0 .*frozen parameters \(eta = 0\)"):
        simulate(import_generated(frozen.path), "implicit_euler", [0.0], [0.0], t_end=1.0, h=0.01)


# Issue 10, item 4: Trajectory.constraint_error of a nonsmooth run --------------------------------

def test_constraint_error_of_a_run_without_constraints_is_none(prandtl):
    traj = simulate(prandtl, "implicit_euler", [0.0], [0.0], t_end=20.0, h=0.01)
    assert traj.element_names == ("slider",)
    assert np.abs(traj.element_state).max() > 0.5        # the slider did load: not all zero
    assert traj.constraint_error is None and traj.velocity_constraint_error is None


# Issue 10, item 4: times that cannot resolve h --------------------------------------------------

def test_times_that_cannot_resolve_the_step_are_refused(cart, capsys):
    with pytest.raises(SimulationError, match=r"t \+ h cannot be told from t") as info:
        simulate(cart, "rk4", Q0, V0, t0=1.7e9, t_end=1.7e9 + 1e-3, h=1e-7)
    assert "h >= 0.238" in str(info.value) and "\n" not in str(info.value)
    code, out, err = cli(capsys, cart.__file__, "--method", "rk4", "--t0", 1.7e9,
                         "--t-end", 1.7e9 + 1e-3, "--h", 1e-7)
    assert_one_line_error(code, err, "cannot be told from t")


def test_large_t0_with_a_resolvable_step_runs_with_distinct_exact_times(cart):
    t0 = 1.7e9                  # float64 spacing 2.4e-7 here: h = 0.25 is resolved to 1e-6 h
    traj = simulate(cart, "rk4", Q0, V0, t0=t0, t_end=t0 + 5.0, h=0.25)
    assert traj.n_steps == 20 and np.all(np.diff(traj.t) == 0.25)


def test_saved_times_do_not_accumulate_rounding(cart):
    """Saved times are t0 + k h rounded once: within one spacing of the exact rational value,
    where a running sum t += h would drift by about n_steps spacings."""
    t0, h, save_every = 0.1, 0.01, 7
    traj = simulate(cart, "rk4", Q0, V0, t0=t0, t_end=t0 + 10_000 * h, h=h, save_every=save_every)
    exact = [float(Fraction(t0) + k * save_every * Fraction(h)) for k in range(len(traj.t) - 1)]
    assert np.abs(traj.t[:-1] - exact).max() <= np.spacing(traj.t[-1])
    drifting = np.cumsum(np.r_[t0, np.full(10_000, h)])[::save_every]
    assert np.abs(drifting - exact).max() > 10 * np.spacing(traj.t[-1])   # what is avoided


# Issue 11: step count and memory -----------------------------------------------------------------

@pytest.mark.parametrize("h, t_end", [(1e-300, 1.0), (1e-12, 1e3), (1e-308, 1e3)])
def test_step_counts_beyond_the_bound_are_refused(cart, capsys, h, t_end):
    code, out, err = cli(capsys, cart.__file__, "--method", "rk4", "--h", h, "--t-end", t_end)
    assert_one_line_error(code, err, "steps, more than the 1e+12")


def test_run_that_does_not_fit_in_memory_is_refused_with_a_save_every(cart, monkeypatch):
    monkeypatch.setattr(run_checks, "available_memory", lambda: 10**6)      # 1 MB
    with pytest.raises(SimulationError, match=r"needs 0\.0088 GB of memory and 0\.001 GB") as info:
        simulate(cart, "rk4", Q0, V0, t_end=100.0, h=1e-3)          # 100001 rows of 11 values
    suggested = int(re.search(r"save_every >= (\d+)", str(info.value)).group(1))
    traj = simulate(cart, "rk4", Q0, V0, t_end=100.0, h=1e-3, save_every=suggested)
    assert run_checks.saved_bytes(len(traj.t), 2, 0) <= 0.5 * 10**6


def test_ten_billion_saved_steps_are_refused_before_allocating(cart, capsys):
    """1e10 steps with save_every = 1 need 880 GB: refused at once, from the real available
    memory, instead of being killed by the OOM killer."""
    code, out, err = cli(capsys, cart.__file__, "--method", "rk4", "--h", 10, "--t-end", 1e11)
    assert_one_line_error(code, err, "needs 880 GB of memory", "--save-every")


# Issue 11: parameters and scalar arguments -------------------------------------------------------

@pytest.mark.parametrize("value, what", [("nan", "nan is not finite"),
                                         ("inf", "inf is not finite")])
def test_non_finite_parameter_on_the_command_line_is_named(cart, capsys, value, what):
    code, out, err = cli(capsys, cart.__file__, "--h", 0.01, "--t-end", 1, "--param", f"k={value}")
    assert_one_line_error(code, err, f"parameter 'k' = {what}")


@pytest.mark.parametrize("kwargs, match", [
    (dict(params={"k": "abc"}), r"parameter 'k' = 'abc' is not a number"),
    (dict(params={"k": math.nan}), r"parameter 'k' = nan is not finite"),
    (dict(params=[1.0, "x", 1.0, 10.0, 9.81]), r"parameter 'm' = 'x' is not a number"),
    (dict(params=[1.0, 2.0]), r"2 parameter values given for 5 parameters"),
    (dict(h=True), r"h must be a finite number, got True"),
    (dict(t_end=np.True_), r"t_end must be a finite number"),
    (dict(save_every=True), r"save_every must be a positive integer, got True"),
    (dict(save_every=math.inf), r"save_every must be a positive integer, got inf"),
    (dict(max_iter="3"), r"max_iter must be a positive integer"),
    (dict(blowup_bound=math.nan), r"blowup_bound must be a number > 0 .*got nan"),
    (dict(blowup_bound=-1.0), r"blowup_bound must be a number > 0"),
    (dict(blowup_bound="big"), r"blowup_bound must be a number > 0"),
    (dict(newton_tol=0.0), r"newton_tol must be a finite number > 0, got 0.0"),
    (dict(newton_always=True), r"method 'midpoint' has no setting 'newton_always'; its "
                               r"settings: newton_tol, max_iter, blowup_bound"),
    (dict(h=None), r"method 'midpoint' has a fixed step: give h"),
    (dict(t_eval=[0.5]), r"t_eval is for the adaptive methods"),
])
def test_bad_api_arguments_are_one_line_errors_naming_them(cart, kwargs, match):
    args = dict(q0=Q0, v0=V0, t_end=1.0, h=0.01)
    args.update(kwargs)
    with pytest.raises(SimulationError, match=match) as info:
        simulate(cart, "midpoint", **args)
    assert "\n" not in str(info.value)


# Issue 10, item 4: energy warning on conservative models -----------------------------------------

def cart_omega_max(q, p):
    """omega_max of K v = omega^2 H v for the cart pendulum, by hand: H from T, K = d2V/dq2 of
    V = k x^2 / 2 - m g l cos(theta)."""
    M, m, l, k, g = (p[name] for name in ("M", "m", "l", "k", "g"))
    c = math.cos(q[1])
    H = np.array([[M + m, m * l * c], [m * l * c, m * l**2]])
    K = np.diag([k, m * g * l * c])
    return math.sqrt(scipy.linalg.eigh(K, H, eigvals_only=True).max())


@pytest.mark.parametrize("method, h, stable", [
    ("midpoint", 2.0, "midpoint is linearly stable for every tau"),
    ("implicit_euler", 1.0, "implicit_euler is stable for every tau, damping"),
])
def test_conservative_run_that_lost_its_energy_warns_once(cart, method, h, stable):
    with pytest.warns(EnergyWarning) as record:
        traj = simulate(cart, method, Q0, V0, t_end=100.0, h=h)
    assert len(record) == 1 and traj.warnings == [str(record[0].message)]
    msg = traj.warnings[0]
    tau = h * cart_omega_max(Q0, traj.params)
    assert f"h omega_max = {tau:.3g} at q0" in msg and stable in msg and "\n" not in msg
    assert f"max |E - E0| = {traj.max_energy_error:.3g}" in msg


def test_accurate_conservative_run_does_not_warn(cart):
    with warnings.catch_warnings():
        warnings.simplefilter("error", EnergyWarning)
        traj = simulate(cart, "midpoint", Q0, V0, t_end=20.0, h=0.01)
    assert traj.warnings == [] and traj.max_energy_error < 1e-3


def test_energy_warning_on_the_command_line_is_one_line(cart, capsys):
    code, out, err = cli(capsys, cart.__file__, "--method", "midpoint", "--h", 2, "--t-end", 100,
                         "--q0", *Q0)
    lines = err.strip().splitlines()
    assert code == 0 and "Traceback" not in err and len(lines) == 1
    assert lines[0].startswith("lagrange-gen: warning: cart_pendulum, midpoint: max |E - E0|")
    assert "h omega_max = " in lines[0] and "steps to t = 100" in out


def test_only_models_whose_flow_conserves_energy_count_as_conservative(generated, cart):
    damped = generated("damped_oscillator")
    p_cart = np.array(cart.DEFAULTS, dtype=float)
    assert is_conservative(cart, np.array(Q0), np.array(V0), 0.0, p_cart)
    assert is_conservative(damped, np.zeros(1), np.zeros(1), 0.0, np.array([1.0, 1.0, 0.0]))
    assert not is_conservative(damped, np.zeros(1), np.zeros(1), 0.0, np.array([1.0, 1.0, 0.3]))
    prandtl = generated("prandtl")              # a time-dependent force and an element
    assert not is_conservative(prandtl, np.zeros(1), np.zeros(1), 0.0,
                               np.array(prandtl.DEFAULTS, dtype=float))
    assert 0 < ENERGY_FRACTION < 1


# Issue 12: the method's settings on the command line come from its spec --------------------------

def test_cli_passes_only_the_settings_given_and_refuses_one_the_method_lacks(cart, capsys):
    code, out, err = cli(capsys, cart.__file__, "--method", "midpoint", "--h", 0.01,
                         "--t-end", 0.1, "--max-iter", 7, "--newton-tol", 1e-10)
    assert code == 0, err
    code, out, err = cli(capsys, cart.__file__, "--method", "rk4", "--h", 0.01, "--t-end", 0.1,
                         "--newton-tol", 1e-10)
    assert_one_line_error(code, err, "method 'rk4' has no setting 'newton_tol'",
                          "its settings: blowup_bound")


def test_cli_has_an_option_for_every_setting_of_every_method(capsys):
    from lagrange_gen.steppers.core import registry
    with pytest.raises(SystemExit):
        main(["simulate", "--help"])
    text = capsys.readouterr().out
    for method in registry.METHODS:
        for name in registry.spec(method).settings._fields:
            assert "--" + name.replace("_", "-") in text, (method, name)
