"""Verdicts of the hard cases (lagrange_gen.analysis.hard_cases) on a few methods: they must come
out failing for a wrong stepper and passing for a right one. No timing asserts."""

from lg_test_support import MODELS_DIR
from lagrange_gen.analysis import hard_cases

FAST = ("explicit_euler", "midpoint", "implicit_euler", "rk4")


def test_explicit_euler_on_fpu_is_reported_failing(gen_dir):
    result = hard_cases.case5_fpu(MODELS_DIR, gen_dir, ["explicit_euler"])
    rows = {row[0]: row for row in result.rows}
    assert rows["explicit_euler"][-1] == hard_cases.FAIL
    assert result.verdict == hard_cases.FAIL


def test_fpu_case_passes_with_a_symplectic_method_and_flags_rk4_drift(gen_dir):
    result = hard_cases.case5_fpu(MODELS_DIR, gen_dir, ["explicit_euler", "midpoint", "rk4"])
    rows = {row[0]: row for row in result.rows}
    assert rows["midpoint"][-1] == hard_cases.PASS
    assert rows["rk4"][-1] == hard_cases.FAIL      # loses the stiff energy at h omega = 0.5
    assert result.verdict == hard_cases.PASS


def test_damped_oscillator_classification(gen_dir):
    result = hard_cases.case4_damped(MODELS_DIR, gen_dir, FAST)
    out = result.data["outcomes"]
    assert out[(1e-6, "midpoint")] == "stiff mode kept"
    assert out[(1e-6, "implicit_euler")] == "over-damped"
    assert out[(1e-6, "explicit_euler")] == hard_cases.GREW
    assert result.verdict == hard_cases.PASS
