"""lagrange-gen bench harness: counts parsed from pytest's output, the report's verdict, and a
plain error outside a checkout (the subprocess run itself is the bench's job, not a test's)."""

from pathlib import Path

import pytest

from lagrange_gen.analysis import harness
from lagrange_gen.errors import LagrangeGenError

SUMMARY = {"profile": "thorough", "models": 340, "failed_models": 0, "kernel_checks": 31000,
           "kinds": {"dynamics": {"py_func": 900, "njit": 120}, "rhs": {"py_func": 90}}}


def test_counts_from_the_last_summary_line():
    output = "....F\nFAILED tests/harness/x.py::t - AssertionError\n1 failed, 13 passed, 2 errors in 691.01s (0:11:31)\n"
    assert harness.parse_counts(output) == {"failed": 1, "passed": 13, "errors": 2}
    assert harness.parse_counts("no summary at all") == {}


@pytest.mark.parametrize("counts, verdict", [({"passed": 14}, "PASS"), ({"passed": 13, "failed": 1}, "FAIL"),
                                             ({}, "FAIL"), ({"passed": 13, "errors": 1}, "FAIL")])
def test_report_states_the_verdict_counts_and_kinds(counts, verdict, tmp_path):
    output = "FAILED tests/harness/test_differential.py::t[elements]\n" if verdict == "FAIL" else ""
    lines, passed = harness.report_lines(tmp_path, output, counts, SUMMARY, 12.3,
                                         ["python", "-m", "pytest", "tests/harness", "--harness-summary=/x"])
    text = "\n".join(lines)
    assert passed == (verdict == "PASS")
    assert f"**{verdict}**" in text and "models drawn and generated: 340" in text
    assert "| `dynamics` | 900 | 120 |" in text and "| `rhs` | 90 | 0 |" in text
    assert "--harness-summary" not in text
    assert ("t[elements]" in text) == (verdict == "FAIL")


def test_outside_a_checkout_says_so(monkeypatch, tmp_path):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(harness, "HARNESS", Path("tests") / "no_such_harness")
    with pytest.raises(LagrangeGenError, match="repository tool"):
        harness.repository_root()
