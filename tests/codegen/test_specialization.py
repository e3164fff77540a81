"""Specializations give the same numbers as the general module: a subset of methods, frozen
parameters, the constant-H factor computed at import; structural zeros are written, never
computed; frozen parameters cannot be passed at run time."""

import inspect
import sys

import numpy as np
import pytest
import sympy as sp

from lg_test_support import MODELS_DIR
from lagrange_gen import SimulationError, load_model, simulate
from lagrange_gen.cli.main import main
from lagrange_gen.codegen import generate_model, generate_text
from lagrange_gen.codegen.needs import MODULE_FUNCTIONS, method_needs
from lagrange_gen.codegen.spec import kernel_table
from lagrange_gen.derive import derive
from lagrange_gen.run.loader import compile_all, import_generated
from lagrange_gen.run.params import resolve_params
from lagrange_gen.steppers.core.registry import METHODS

sys.path.insert(0, str(MODELS_DIR))
from n_link_pendulum import n_link_pendulum  # noqa: E402

RTOL = 1e-12


def _generate(tmp_path, model, **kwargs):
    tmp_path.mkdir(parents=True, exist_ok=True)
    model.source_path = model.source_path or str(tmp_path / "model.py")
    text, _, target = generate_text(model, tmp_path, **kwargs)
    target.write_text(text)
    return import_generated(target)


def test_method_needs_are_read_from_the_stepper_sources():
    # (N_COORDS: the loop bound of every step, steppers/core/options.py "Loop bounds")
    assert method_needs("explicit_euler", with_loop=False) == {"forward_dynamics", "N_COORDS"}
    # the run loop adds the energy of saved states and the event functions (and, to
    # interpolate a step with events, the forward dynamics and the model's counts)
    assert {"energy", "events", "N_EVENTS"} <= method_needs("explicit_euler")
    # composition calls verlet.step through `from . import verlet`: verlet's needs are inherited
    assert method_needs("verlet") <= method_needs("composition")
    assert {"momentum_rate_jacobian", "mass_matvec_dq"} <= method_needs("midpoint")
    assert "rhs_jacobian" not in method_needs("midpoint")
    kernels = set(kernel_table(derive(load_model(MODELS_DIR / "double_pendulum.py"))))
    # the contacts kernel only a model with unilateral contacts has, the nonholonomic kernel
    # only a model with velocity constraints
    kernels |= set(kernel_table(derive(load_model(MODELS_DIR / "bouncing_ball.py"))))
    kernels |= set(kernel_table(derive(load_model(MODELS_DIR / "chaplygin_sleigh.py"))))
    for method in METHODS:
        functions = {n for n in method_needs(method) if not n.isupper()}
        assert functions <= kernels | set(MODULE_FUNCTIONS), method


def test_methods_subset_emits_only_what_they_need_and_steps_identically(tmp_path, generated):
    general = generated("double_pendulum")
    subset = generate_model(MODELS_DIR / "double_pendulum.py", tmp_path, methods=["verlet", "midpoint"])
    mod = import_generated(subset.path)
    assert set(mod.KERNELS) < set(general.KERNELS)
    assert not hasattr(mod, "rhs_jacobian") and not hasattr(mod, "run_rk4")
    assert "not emitted (no requested method uses them): rhs_jacobian" in mod.__doc__
    compile_all(mod)                          # must not reach for kernels that are not there
    q0, v0 = np.array([0.7, -0.4]), np.array([0.2, 0.9])
    a = simulate(general, "midpoint", q0, v0, t_end=0.2, h=0.01)
    b = simulate(mod, "midpoint", q0, v0, t_end=0.2, h=0.01)
    np.testing.assert_allclose(b.q, a.q, rtol=RTOL, atol=1e-14)
    np.testing.assert_allclose(b.v, a.v, rtol=RTOL, atol=1e-14)


def test_frozen_parameters_fold_into_constants_with_the_same_results(tmp_path, generated):
    general = generated("n_link_pendulum")                  # n = 3, defaults g = 9.81, l = 1
    frozen = _generate(tmp_path, load_model(MODELS_DIR / "n_link_pendulum.py"),
                       methods=["rk4"], freeze={"g": 9.81, "l": 1.0})
    assert frozen.PARAMS == ("m",) and frozen.FROZEN == {"g": 9.81, "l": 1.0}
    assert "frozen parameters (folded into the kernels, FROZEN): g = 9.81, l = 1.0" in frozen.__doc__
    rng = np.random.default_rng(5)
    for _ in range(5):
        q, v = rng.uniform(-2, 2, 3), rng.uniform(-2, 2, 3)
        np.testing.assert_allclose(frozen.accelerations(q, v, 0.0, {"m": 1.7}),
                                   general.accelerations(q, v, 0.0, {"m": 1.7}), rtol=RTOL)
    q0, v0 = np.array([0.5, -0.3, 0.2]), np.array([0.0, 0.4, -0.1])
    a = simulate(general, "rk4", q0, v0, t_end=0.3, h=0.01, params={"m": 1.7})
    b = simulate(frozen, "rk4", q0, v0, t_end=0.3, h=0.01, params={"m": 1.7})
    np.testing.assert_allclose(b.q, a.q, rtol=RTOL, atol=1e-14)


def test_frozen_parameters_cannot_be_passed_at_run_time(tmp_path):
    mod = _generate(tmp_path, n_link_pendulum(2), methods=["rk4"], freeze={"g": 9.81})
    q = np.zeros(2)
    with pytest.raises(SimulationError, match=r"parameter 'g' is frozen at 9.81 .*--freeze"):
        mod.accelerations(q, q, 0.0, {"g": 3.0})
    with pytest.raises(SimulationError, match="frozen, not passed: g"):
        mod.accelerations(q, q, 0.0, [1.0, 1.0, 9.81])
    with pytest.raises(SimulationError, match="frozen"):
        resolve_params(mod.PARAMS, mod.DEFAULTS, {"g": 3.0}, "m", frozen=mod.FROZEN)
    with pytest.raises(SimulationError, match="'g'"):
        simulate(mod, "rk4", q, q, t_end=0.01, h=0.01, params={"g": 3.0})


def test_simulate_says_the_parameter_is_frozen(tmp_path):
    mod = _generate(tmp_path, n_link_pendulum(1), methods=["rk4"], freeze={"g": 9.81})
    with pytest.raises(SimulationError, match="frozen"):
        simulate(mod, "rk4", [0.1], [0.0], t_end=0.01, h=0.01, params={"g": 3.0})


@pytest.mark.parametrize("stem", ["spring_mass_chain", "fpu"])
def test_constant_mass_matrix_is_factored_at_import(generated, stem):
    mod = generated(stem)
    n = mod.N_COORDS
    assert mod.MASS_IS_CONSTANT and "factored once at import" in mod.__doc__
    H, rhs = np.empty((n, n)), np.empty(n)
    mod.mass_matrix(np.zeros(n), 0.0, mod.DEFAULT_PARAMS, H)
    L = mod.MASS_FACTOR
    np.testing.assert_array_equal(L, np.tril(L))
    np.testing.assert_allclose(L @ L.T, H, rtol=1e-14, atol=1e-14)
    rng = np.random.default_rng(9)
    scaled = mod.DEFAULT_PARAMS * 1.5                     # not the defaults: the general path
    for p in (mod.DEFAULT_PARAMS, scaled):
        q, v = rng.uniform(-1, 1, n), rng.uniform(-1, 1, n)
        mod.dynamics(q, v, 0.3, p, H, rhs)
        np.testing.assert_allclose(mod.accelerations(q, v, 0.3, p), np.linalg.solve(H, rhs), rtol=RTOL)
    source = inspect.getsource(mod.forward_dynamics.py_func)
    assert "MASS_FACTOR" in source and "    dynamics(" not in source


def test_structural_zeros_are_written_not_computed(generated, derived):
    mod, dyn = generated("spring_mass_chain"), derived("spring_mass_chain")
    n = dyn.n
    zero = [i * n + j for i in range(n) for j in range(n) if dyn.H[i, j] == 0]
    source = inspect.getsource(mod.mass_matrix.py_func)
    # n = 4: a small output, stored as H[i, j] (codegen.emit.FLAT_VIEW_MIN): each zero entry is
    # stored once, as the constant, and never computed
    assert zero and all(source.count(f"H[{k // n}, {k % n}]") == 1 and
                        f"H[{k // n}, {k % n}] = 0.0" in source for k in zero)
    H = np.full((n, n), np.nan)                        # whatever the caller's array held
    mod.mass_matrix(np.zeros(n), 0.0, mod.DEFAULT_PARAMS, H)
    assert np.all(H.ravel()[zero] == 0.0) and np.all(np.isfinite(H))
    assert dyn.jac["dHw_dq"] == sp.zeros(n, n)
    assert "mass_matvec_dq 16/16" in mod.__doc__


def test_cli_freeze_and_its_errors(tmp_path, capsys):
    model = MODELS_DIR / "n_link_pendulum.py"
    assert main([str(model), "-o", str(tmp_path), "--freeze", "g=9.81,l=1", "--methods", "rk4"]) == 0
    assert import_generated(tmp_path / "n_link_pendulum_3.py").PARAMS == ("m",)
    assert main([str(model), "-o", str(tmp_path), "--freeze", "gravity=9.81"]) == 2
    assert "cannot freeze gravity: not a parameter (parameters: m, l, g)" in capsys.readouterr().err
    assert main([str(model), "-o", str(tmp_path), "--freeze", "g=abc"]) == 2
    assert "expected NAME=NUMBER" in capsys.readouterr().err


def test_composed_kernels_equal_the_symbolic_ones(tmp_path):
    """verlet + midpoint compose dynamics and momentum_rate_jacobian from other kernels
    (codegen.compose); a kernel library (no methods) has them fully symbolic."""
    composed = _generate(tmp_path / "c", n_link_pendulum(3), methods=["verlet", "midpoint"])
    symbolic = _generate(tmp_path / "s", n_link_pendulum(3), methods=[])
    assert "composed from kernels" in composed.__doc__ and "composed" not in symbolic.__doc__
    for name in ("dynamics", "momentum_rate_jacobian"):     # each of the two, not one of them
        assert "composed" in getattr(composed, name).py_func.__doc__, name
    rng = np.random.default_rng(21)
    p = composed.DEFAULT_PARAMS * np.array([1.3, 0.8, 1.1])
    out = {m: [np.empty((3, 3)), np.empty(3), np.empty((3, 3)), np.empty((3, 3))] for m in ("c", "s")}
    for _ in range(5):
        q, v = rng.uniform(-2, 2, 3), rng.uniform(-2, 2, 3)
        for key, mod in (("c", composed), ("s", symbolic)):
            H, rhs, Jq, Jqd = out[key]
            mod.dynamics(q, v, 0.0, p, H, rhs)
            mod.momentum_rate_jacobian(q, v, 0.0, p, Jq, Jqd)
        for a, b in zip(out["c"], out["s"]):
            np.testing.assert_allclose(a, b, rtol=RTOL, atol=1e-13 * np.abs(b).max())


def test_needs_follow_newton_assemblies_bound_at_module_level():
    """partitioned.py passes its assemblies to newton.solve as module-level problems
    (``_KICK = newton.problem(name, assemble_kick)``): the kernels they use are verlet's needs
    (the generalized leapfrog's Newton uses the momentum rate and its Jacobian)."""
    from lagrange_gen.codegen.needs import method_needs
    newton = {"momentum_rate", "momentum_rate_jacobian"}       # the kick's residual and Jacobian
    assert newton | {"mass_matvec_dq"} <= method_needs("verlet")  # and the drift's
    assert newton | {"mass_matvec_dq"} <= method_needs("composition")
    assert newton <= method_needs("symplectic_euler")


def test_large_outputs_go_through_the_flat_view_with_a_zero_loop(tmp_path):
    """A 5 x 5 diagonal H (25 entries > FLAT_VIEW_MIN): stored through H_f, its 20 structural
    zeros by a loop over a module constant of flat indices (codegen.emit)."""
    model = tmp_path / "five_masses.py"
    model.write_text(
        "from lagrange_gen import Model, coordinates, parameters\n"
        "xs = coordinates('x0 x1 x2 x3 x4')\n"
        "k = parameters('k', defaults=(2.0,))\n"
        "T = sum((i + 1) * x.d**2 / 2 for i, x in enumerate(xs))\n"
        "V = sum(k * (a - b)**2 / 2 for a, b in zip(xs, xs[1:])) + k * xs[0]**2 / 2\n"
        "model = Model('five_masses', coords=list(xs), T=T, V=V)\n")
    mod = import_generated(generate_model(model, tmp_path / "out", methods=["rk4"]).path)
    zero = [i * 5 + j for i in range(5) for j in range(5) if i != j]
    assert list(mod._ZEROS_MASS_MATRIX_H) == zero
    assert "H_f = H.reshape(25)" in inspect.getsource(mod.mass_matrix.py_func)
    H = np.full((5, 5), np.nan)
    mod.mass_matrix(np.zeros(5), 0.0, mod.DEFAULT_PARAMS, H)
    np.testing.assert_array_equal(H, np.diag([1.0, 2.0, 3.0, 4.0, 5.0]))
