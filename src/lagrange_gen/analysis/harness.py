"""The verdict of a run of the differential harness (tests/harness) and the lines of its report:
counts parsed from pytest's output, PASS only when something passed and nothing failed or
errored. ``lagrange-gen bench harness`` runs the harness in a subprocess and writes the report.
The harness is a repository tool: the tests are not installed with the package.
"""

from __future__ import annotations

import platform
import re
import subprocess
from datetime import datetime, timezone
from pathlib import Path

from ..errors import LagrangeGenError
from .runs import md_table

HARNESS = Path("tests") / "harness"
_COUNT = re.compile(r"(\d+) (passed|failed|errors?|skipped|deselected|xfailed|xpassed)")


def repository_root() -> Path:
    """The checkout holding tests/harness: the working directory or the one this package lives
    in (an editable install). LagrangeGenError, saying so plainly, when neither has it."""
    for candidate in (Path.cwd(), Path(__file__).resolve().parents[3]):
        if (candidate / HARNESS / "test_differential.py").is_file():
            return candidate
    raise LagrangeGenError(f"bench harness: no {HARNESS}/ in {Path.cwd()} or next to the installed package: "
                           "the harness is a repository tool, run it from a lagrange-gen checkout")


def _git(root, *args):
    try:
        out = subprocess.run(["git", *args], cwd=root, capture_output=True, text=True, timeout=30)
    except (OSError, subprocess.SubprocessError):
        return ""
    return out.stdout.strip() if out.returncode == 0 else ""


def parse_counts(output: str) -> dict:
    """{"passed": 12, "failed": 1, ...} from pytest's last summary line ("error" as "errors")."""
    lines = [line for line in output.splitlines() if _COUNT.search(line) and " in " in line]
    counts = {}
    for number, word in _COUNT.findall(lines[-1] if lines else ""):
        counts["errors" if word.startswith("error") else word] = int(number)
    return counts


def report_lines(root, output, counts, summary, wall, cmd):
    """The markdown of reports/harness.md."""
    passed = counts.get("failed", 0) == 0 and counts.get("errors", 0) == 0 and counts.get("passed", 0) > 0
    commit = _git(root, "rev-parse", "--short", "HEAD") or "unknown"
    dirty = " (with uncommitted changes)" if _git(root, "status", "--porcelain", "--", "src", "tests") else ""
    versions = {name: _version(name) for name in ("sympy", "symengine", "numba", "hypothesis")}
    shown = " ".join(["python"] + [a for a in cmd[1:] if not a.startswith("--harness-summary")])
    lines = ["# Differential harness", "",
             f"Profile `{summary.get('profile', '?')}`, run from the repository root: `{shown}`", "",
             f"- date: {datetime.now(timezone.utc).strftime('%Y-%m-%d %H:%M UTC')}",
             f"- commit: {commit}{dirty}",
             f"- Python {platform.python_version()}, " + ", ".join(f"{k} {v}" for k, v in versions.items()),
             f"- result: **{'PASS' if passed else 'FAIL'}** ("
             + ", ".join(f"{v} {k}" for k, v in sorted(counts.items())) + ")",
             f"- wall time: {wall:.0f} s",
             f"- models drawn and generated: {summary.get('models', '?')}",
             f"- kernel checks (one kernel, or one finite-difference check, at one state): "
             f"{summary.get('kernel_checks', '?')}", ""]
    kinds = summary.get("kinds", {})
    if kinds:
        lines += ["Checks per kernel kind, running the printed source as Python (py_func) and compiled (njit):", ""]
        lines += md_table(["kernel kind", "py_func", "njit"],
                          [[f"`{k}`", v.get("py_func", 0), v.get("njit", 0)] for k, v in sorted(kinds.items())])
    failures = [line for line in output.splitlines() if line.startswith(("FAILED", "ERROR"))]
    if failures:
        lines += ["", "Failures:", "", "```", *failures[:40], "```"]
    return lines, passed


def _version(name):
    try:
        from importlib.metadata import version
        return version(name)
    except Exception:  # noqa: BLE001  not installed
        return "absent"
