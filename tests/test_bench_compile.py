"""`lagrange-gen bench compile`: the report writer and the suite's wiring (no timings here)."""

from lagrange_gen.bench import cli
from lagrange_gen.bench.compile import configurations, write_report
from lagrange_gen.jit.speedups import NAMES


def test_the_report_gives_each_speedup_a_ratio(tmp_path):
    times = {label: 2.0 for label, _ in configurations()}
    times["all"] = 1.0
    text = write_report({"case": times}, tmp_path / "compile.md", "0.68.1")
    assert (tmp_path / "compile.md").read_text() == text
    for name in NAMES:
        assert f"without {name}" in text
    assert "2.00 s (2.00x)" in text and "| case | 1.00 s |" in text


def test_wired_as_a_suite():
    assert "compile" in cli.SUITES
    assert [v for _, v in configurations()][0] == "all"
    assert "none" in [v for _, v in configurations()]
