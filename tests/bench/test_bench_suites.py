"""The suites themselves with quick settings on a few methods: verdicts that must come out
failing for a wrong stepper, and report files with real figures. No timing asserts."""

import numpy as np
import pytest

from bench_util import MODELS, gen_dir, png_ok
from lagrange_gen.bench import hard_cases, report

FAST = ("explicit_euler", "midpoint", "implicit_euler", "rk4")


def test_explicit_euler_on_fpu_is_reported_failing():
    result = hard_cases.case5_fpu(MODELS, gen_dir(), ["explicit_euler"])
    rows = {row[0]: row for row in result.rows}
    assert rows["explicit_euler"][-1] == hard_cases.FAIL
    assert result.verdict == hard_cases.FAIL


def test_fpu_case_passes_with_a_symplectic_method_and_flags_rk4_drift():
    result = hard_cases.case5_fpu(MODELS, gen_dir(), ["explicit_euler", "midpoint", "rk4"])
    rows = {row[0]: row for row in result.rows}
    assert rows["midpoint"][-1] == hard_cases.PASS
    assert rows["rk4"][-1] == hard_cases.FAIL      # loses the stiff energy at h omega = 0.5
    assert result.verdict == hard_cases.PASS


def test_damped_oscillator_classification():
    result = hard_cases.case4_damped(MODELS, gen_dir(), FAST)
    out = result.data["outcomes"]
    assert out[(1e-6, "midpoint")] == "stiff mode kept"
    assert out[(1e-6, "implicit_euler")] == "over-damped"
    assert out[(1e-6, "explicit_euler")] == hard_cases.GREW
    assert result.verdict == hard_cases.PASS


@pytest.fixture(scope="module")
def quick_report(tmp_path_factory):
    reports = tmp_path_factory.mktemp("reports")
    results = report.run_report(MODELS, gen_dir(), reports, quick=True, progress=False,
                                methods=FAST, precision_cases=("cart_pendulum",),
                                scene_keys=("oscillator_c1e-06",), hard_cases=(3, 4, 6))
    return reports, results


def test_report_files_are_written(quick_report):
    reports, _ = quick_report
    for name in ("precision.md", "stability.md", "hard.md", "summary.md"):
        text = (reports / name).read_text()
        assert text.startswith("# ") and len(text) > 200, name
    summary = (reports / "summary.md").read_text()
    assert "Which method for which scene" in summary and "scipy DOP853" in summary


def test_figures_are_nonempty_pngs(quick_report):
    reports, _ = quick_report
    for name in ("precision_cart_pendulum.png", "stability_tau.png",
                 "hard_damped_oscillator.png"):
        assert png_ok(reports / name), name


def test_precision_points_are_measured_against_the_reference(quick_report):
    _, results = quick_report
    cart = results["precision"]["results"][0]
    rk4 = [pt for pt in cart["points"] if pt.method == "rk4" and not pt.failed]
    errors = [pt.final for pt in rk4]
    # fourth order: halving h divides the error by about 16
    ratios = np.array(errors[1:-1]) / np.array(errors[2:])
    assert np.all((ratios > 10) & (ratios < 24)), errors
    assert cart["reference"].agreement < 1e-9


def test_method_choice_follows_the_measurements(quick_report):
    _, results = quick_report
    rows = {scene: pick for scene, pick, _ in report.choice_rows(
        results["precision"]["results"], results["stability"], results["hard"]["results"])}
    assert rows["stiff modes the scene does not care about"] == "implicit_euler"
    assert rows["h omega >> 1, no damping allowed"] == "midpoint"
