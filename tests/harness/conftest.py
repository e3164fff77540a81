"""Options of the differential harness (initial conftest only when pytest is given tests/harness
or a file in it: ``python -m pytest tests/harness --thorough``).

--thorough          the thorough profile (profiles.py)
--printer-bug       put the issue-10 printer bug back for the whole run and count the failing
                    examples instead of failing (the mutation demonstration)
--harness-summary   write the run's counts as JSON to this path (bench harness reads it)
"""

import json

from . import profiles
from .check import CHECKED, STATS
from .printer_bug import put_back


def pytest_addoption(parser):
    group = parser.getgroup("harness", "differential harness (tests/harness)")
    group.addoption("--thorough", action="store_true", help="draw hundreds of models (thorough profile)")
    group.addoption("--printer-bug", action="store_true",
                    help="put the old a/x**2 -> a/x*x printer bug back and count failing examples")
    group.addoption("--harness-summary", metavar="PATH", help="write the harness counts as JSON here")


def pytest_configure(config):
    bug = config.getoption("printer_bug", default=False)
    profiles.select("thorough" if config.getoption("thorough", default=False) else "ci", count_only=bug)
    if bug:
        put_back()


def summary():
    """{profile, models, failed_models, kernel_checks, kinds: {kind: {mode: count}}}."""
    kinds = {}
    for (kind, mode), count in sorted(CHECKED.items()):
        kinds.setdefault(kind, {})[mode] = count
    return {"profile": profiles.current()["name"], "models": STATS["models"],
            "failed_models": STATS["failed models"], "kernel_checks": sum(CHECKED.values()), "kinds": kinds}


def pytest_terminal_summary(terminalreporter, config):
    s = summary()
    path = config.getoption("harness_summary", default=None)
    if path:
        with open(path, "w") as fh:
            json.dump(s, fh, indent=1, sort_keys=True)
    if s["models"]:
        bug = config.getoption("printer_bug", default=False)
        terminalreporter.write_line(
            f"harness ({s['profile']}): {s['models']} models drawn, {s['kernel_checks']} kernel checks, "
            f"{len(s['kinds'])} kernel kinds" + (f", {s['failed_models']} models failed (--printer-bug)" if bug else ""))
