"""`lagrange-gen bench harness`: the differential harness's thorough profile, with its report.

The harness (tests/harness) draws random models over the grammar users write and compares every
kernel their generated modules emit with a reference written from Lagrange's equations in plain
sympy, and every Jacobian kernel with finite differences. CI runs its small profile; this suite
runs ``python -m pytest tests/harness --thorough -q`` from the repository root in a subprocess
and writes reports/harness.md (date, commit, models drawn, kernel checks, pass/fail, wall time).
It is a repository tool: the tests are not installed with the package.
"""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from ..analysis.harness import HARNESS, parse_counts, report_lines, repository_root
from ..errors import LagrangeGenError
from .common import write_report


def run_harness_tests(root, thorough=True, extra=()):
    """Run the harness in a subprocess: (pytest output, counts, summary dict, wall seconds)."""
    with tempfile.TemporaryDirectory() as tmp:
        summary_path = Path(tmp) / "summary.json"
        cmd = [sys.executable, "-m", "pytest", str(HARNESS), "-q", "-p", "no:cacheprovider",
               f"--harness-summary={summary_path}", *(["--thorough"] if thorough else []), *extra]
        start = time.perf_counter()
        proc = subprocess.run(cmd, cwd=root, capture_output=True, text=True)
        wall = time.perf_counter() - start
        summary = json.loads(summary_path.read_text()) if summary_path.is_file() else {}
    output = proc.stdout + proc.stderr
    return output, parse_counts(output), summary, wall, cmd


def run_harness_bench(reports_dir="reports", thorough=True):
    """Run the harness and write reports_dir/harness.md; LagrangeGenError when it failed."""
    root = repository_root()
    output, counts, summary, wall, cmd = run_harness_tests(root, thorough)
    lines, passed = report_lines(root, output, counts, summary, wall, cmd)
    path = write_report(Path(reports_dir) / "harness.md", lines)
    print("\n".join(lines))
    if not passed:
        counted = ", ".join(f"{v} {k}" for k, v in sorted(counts.items())) or "no test summary"
        raise LagrangeGenError(f"bench harness: the differential harness failed ({counted}); see {path}")
    return path
