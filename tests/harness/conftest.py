"""What the differential harness's options do (the options themselves are registered in
tests/conftest.py, so they work from the repository root: ``python -m pytest --thorough``).

--thorough          the thorough profile (profiles.py)
--printer-bug       put the issue-10 printer bug back for the whole run and count the failing
                    examples instead of failing (the mutation demonstration)
--harness-summary   write the run's counts as JSON to this path (bench harness reads it)
"""

import json

from . import profiles
from .check import CHECKED, STATS
from .printer_bug import put_back


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
