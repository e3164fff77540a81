"""The stepper specs (steppers/core/method_spec.py) are the one place that knows a method.

- each SPEC's declared kernels are what its code reaches (codegen.needs reads the source);
- no source file outside steppers/ compares anything with a method's name (the CLI, simulate,
  the generator, the analysis and the bench read the spec instead);
- a settings record refuses what it does not have and checks what it has.
"""

import ast
import math
from pathlib import Path

import pytest

from lagrange_gen.codegen.needs import method_needs
from lagrange_gen.errors import SimulationError
from lagrange_gen.steppers.core import registry
from lagrange_gen.steppers.core.method_spec import FAMILIES, make_settings

SRC = Path(__file__).resolve().parents[2] / "src" / "lagrange_gen"


@pytest.mark.parametrize("method", registry.METHODS)
def test_declared_kernels_are_what_the_code_calls(method):
    """SPEC.kernels: the generated kernels the method's own code reaches (the run loop's,
    energy and events, come on top)."""
    called = {name for name in method_needs(method, with_loop=False) if name.islower()}
    assert set(registry.spec(method).kernels) == called


@pytest.mark.parametrize("method", registry.METHODS)
def test_spec_is_complete(method):
    spec = registry.spec(method)
    assert spec.name == method and spec.family in FAMILIES and spec.order >= 1
    assert spec.summary and "blowup_bound" in spec.settings._fields
    assert all(isinstance(w, int) or w in ("n", "m", "m1", "ne", "c", "r", "r1")
               for _, w in spec.saved)
    if not (spec.constraints or spec.elements or spec.adaptive or spec.contacts
            or spec.nonholonomic):
        assert spec.stable_tau is not None and spec.rho is not None, \
            "a fixed-step unconstrained method declares its linear stability"
    if spec.constraints:
        assert spec.constraint_drift in ("none", "bounded", "grows")


def _method_name_comparisons(path):
    """(line, name) of every comparison in a source file involving a method-name literal."""
    names = set(registry.METHODS)
    found = []
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Compare):
            for side in (node.left, *node.comparators):
                for leaf in ast.walk(side):
                    if isinstance(leaf, ast.Constant) and leaf.value in names:
                        found.append((node.lineno, leaf.value))
    return found


def test_no_file_outside_the_steppers_tests_a_method_name():
    offenders = [f"{path.relative_to(SRC)}:{line}: {name!r}"
                 for path in sorted(SRC.rglob("*.py")) if "steppers" not in path.parts
                 for line, name in _method_name_comparisons(path)]
    assert not offenders, "method names tested outside steppers/: " + "; ".join(offenders)


def test_the_scan_finds_a_comparison(tmp_path):
    """The scan above can fail: it sees the forms a name test takes."""
    probe = tmp_path / "probe.py"
    probe.write_text('if method == "rattle" or m in ("verlet", "x"):\n    pass\n')
    assert [name for _, name in _method_name_comparisons(probe)] == ["rattle", "verlet"]


def test_settings_are_typed_and_validated():
    spec = registry.spec("midpoint")
    record = make_settings(spec, {"max_iter": 7, "newton_tol": 1e-9})
    assert record.max_iter == 7 and isinstance(record.max_iter, int)
    assert record.newton_tol == 1e-9 and record.blowup_bound == 1e150
    with pytest.raises(SimulationError, match="method 'midpoint' has no setting 'compliance'"):
        make_settings(spec, {"compliance": 1.0})
    with pytest.raises(SimulationError, match="max_iter must be a positive integer, got 2.5"):
        make_settings(spec, {"max_iter": 2.5})
    with pytest.raises(SimulationError, match="newton_tol must be a finite number > 0, got -1"):
        make_settings(spec, {"newton_tol": -1})
    with pytest.raises(SimulationError, match=r"blowup_bound must be a number > 0 \(math.inf: no bound\), got nan"):
        make_settings(spec, {"blowup_bound": math.nan})
    assert make_settings(spec, {"blowup_bound": math.inf}).blowup_bound == math.inf


def test_constrained_settings_limits():
    spook = registry.spec("spook")
    with pytest.raises(SimulationError, match="compliance must be a finite number >= 0"):
        make_settings(spook, {"compliance": -1.0})
    with pytest.raises(SimulationError, match="relaxation must be a finite number > 0"):
        make_settings(spook, {"relaxation": 0.0})
    index1 = registry.spec("index1")
    assert make_settings(index1, {"baumgarte": [1, 2]}).baumgarte == (1.0, 2.0)
    with pytest.raises(SimulationError, match="baumgarte must be 2 numbers"):
        make_settings(index1, {"baumgarte": 3.0})


def test_applicability_comes_from_the_specs():
    for method in registry.METHODS:
        spec = registry.spec(method)
        on_plain = registry.inapplicable(method, 0, 0)
        assert bool(on_plain) == (spec.constraints or spec.contacts or spec.nonholonomic)
        assert bool(registry.inapplicable(method, 2, 0)) != spec.constraints
        assert bool(registry.inapplicable(method, 0, 0, 1)) != spec.contacts
        assert bool(registry.inapplicable(method, 0, 0, 0, 1)) != spec.nonholonomic
        assert not registry.inapplicable(method, 0, 1) or not spec.elements
    assert registry.runs_as("implicit_euler", 1) == "nonsmooth_euler"
    assert registry.runs_as("implicit_euler", 0) == "implicit_euler"
