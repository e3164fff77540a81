"""The differential harness: random models over the users' grammar, every kernel their modules
emit against a reference written from Lagrange's equations in plain sympy (reference.py) and
every Jacobian kernel against finite differences (fd.py), as printed Python and compiled.

Model classes (CASES) are chosen so that together they emit every kernel kind: H(q) models emit
the symbolic kernels, constrained ones generated for rattle (whose callers of the dynamics all
use the momentum rate, as verlet's and midpoint's do) get the composed dynamics and
momentum_rate_jacobian,
constant-H models the rhs kernel and the pre-factored forward dynamics,
constrained models the constraint kernels, models with elements the element kernels, models
with unilateral contacts the contacts kernel (gap, W_N, W_T, coefficients), contact_bias and contact_rates,
models with velocity constraints the nonholonomic kernels (A, b, gamma and their derivatives;
with holonomic constraints too, d gamma/dq of those);
test_every_kernel_kind_was_checked asserts it. Profiles: profiles.py.
"""

import pytest
import sympy as sp
from hypothesis import given, strategies as st

from lagrange_gen.codegen.compose import composed_spec
from lagrange_gen.codegen.printer import KernelPrinter
from lagrange_gen.codegen.spec import kernel_table
from lagrange_gen.derive import derive

from . import profiles
from .check import (BODY_KERNELS, CHECKED, CONTACT_KERNELS, CONTRACT, NONHOLONOMIC_KERNELS,
                    SENSITIVITY_KERNELS, STATS, check_model)
from .printer_bug import put_back
from .strategies import kepler, models

MODES = ("py_func", "njit")
#: model class -> (strategy options, methods the module is generated for)
CASES = {
    "smooth": (dict(), []),
    "constrained, composed": (dict(constrained=True), ["rattle"]),
    "constant mass": (dict(constant_mass=True), []),
    "constrained": (dict(constrained=True), []),
    "elements": (dict(elements=True), []),
    "contacts": (dict(contacts=True), []),
    # velocity constraints beside holonomic ones: every nonholonomic kernel kind in one class
    "constrained, nonholonomic": (dict(constrained=True, nonholonomic=True), []),
}
HARNESS_TESTS = ("test_kernels_as_python_match_reference", "test_compiled_kernels_match_reference",
                 "test_native_kernels_match_reference", "test_kepler_kernels_match_reference")


def _run(case, data, out_dir, modes):
    options, methods = CASES[case]
    drawn = data.draw(models(**options), label="model")
    seed = data.draw(st.integers(0, 2**32 - 1), label="state seed")
    _verdict(check_model(drawn, methods, out_dir, modes, seed, profiles.current()["states"]))


def _verdict(failures):
    """Count the model; fail with the first mismatches (or, under --printer-bug, count them)."""
    STATS["models"] += 1
    if profiles.current()["count_only"]:
        STATS["failed models"] += bool(failures)
        return
    assert not failures, "\n".join(failures[:12])


@pytest.mark.parametrize("case", CASES)
@profiles.hypothesis_settings("py_func")
@given(data=st.data())
def test_kernels_as_python_match_reference(case, data, tmp_path_factory):
    _run(case, data, tmp_path_factory.mktemp("harness"), ("py_func",))


@pytest.mark.parametrize("case", CASES)
@profiles.hypothesis_settings("njit")
@given(data=st.data())
def test_compiled_kernels_match_reference(case, data, tmp_path_factory):
    _run(case, data, tmp_path_factory.mktemp("harness"), MODES)


@pytest.mark.parametrize("case", CASES)
@profiles.hypothesis_settings("native")
@given(data=st.data())
def test_native_kernels_match_reference(case, data, tmp_path_factory):
    """The kernels lowered to LLVM without numba (jit/native.py), as the portable glue calls
    them, against the same reference: every construct of the users' grammar the printer writes
    must lower, or the test names the kernel and construct it could not."""
    _run(case, data, tmp_path_factory.mktemp("harness"), ("native",))


def test_kepler_kernels_match_reference(tmp_path):
    """The model of issue 10, whose momentum_rate read -1/q_0*q_0 + ... before the fix."""
    _verdict(check_model(kepler(), [], tmp_path, MODES, seed=10, n_states=3))


def test_printer_bug_put_back_is_detected(monkeypatch, tmp_path):
    """The harness can fail: with a/x**2 printed a/x*x again, Kepler's kernels disagree."""
    put_back(monkeypatch)
    x, a = sp.symbols("x a")
    assert KernelPrinter().doprint(a / x**2) == "a/x*x"          # the bug really is back
    failures = check_model(kepler(), [], tmp_path, ("py_func",), seed=10, n_states=2)
    assert any(f.startswith("py_func: momentum_rate.momentum_rate") for f in failures), failures


def _expected_kinds():
    """Every kernel kind a module can hold, from the generator's own table (names only)."""
    drawn = kepler()
    dyn = derive(drawn.build())
    table = kernel_table(dyn)
    # the kernels of body models are checked on spatial trees (test_spatial_trees.py), the
    # parameter derivatives of sensitivities in tests/gradients (check.SENSITIVITY_KERNELS)
    table = {name: spec for name, spec in table.items() if name not in SENSITIVITY_KERNELS}
    assert set(table) | set(BODY_KERNELS) | set(CONTACT_KERNELS) | set(NONHOLONOMIC_KERNELS) \
        == set(CONTRACT), "a kernel was added or removed: update check.CONTRACT"
    kinds = set(table) | set(CONTACT_KERNELS) | set(NONHOLONOMIC_KERNELS) | {"accelerations", "forward_dynamics[general]", "forward_dynamics[factored]",
                          "forward_dynamics[factored, other parameters]"}
    for name in table:
        try:
            composed_spec(name, dyn)
        except KeyError:
            continue
        kinds.add(f"{name}[composed]")
    kinds |= {f"fd:{name}" for name in ("rhs_jacobian", "momentum_rate_jacobian", "mass_matvec_dq",
                                        "constraints", "constraint_dq", "elements", "elements_hessian",
                                        "contacts", "contact_bias", "contact_rates")}
    return kinds


def test_every_kernel_kind_was_checked(request):
    """Coverage of this run: every kernel kind (and composed kernel, forward-dynamics path and
    finite-difference check) was compared at least once as Python, compiled by numba and
    lowered natively."""
    ran = {item.originalname for item in request.session.items}
    if not set(HARNESS_TESTS) <= ran:
        pytest.skip("coverage is judged on a run of the whole harness")
    missing = sorted(f"{kind} ({mode})" for kind in _expected_kinds()
                     for mode in (*MODES, "native") if not CHECKED[(kind, mode)])
    assert not missing, f"never checked: {', '.join(missing)}"
