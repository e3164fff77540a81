"""What the differential harness's options do (the options themselves are registered in
tests/conftest.py, so they work from the repository root: ``python -m pytest --thorough``).

--thorough          the thorough profile (profiles.py)
--printer-bug       put the issue-10 printer bug back for the whole run and count the failing
                    examples instead of failing (the mutation demonstration)
--harness-summary   write the run's counts as JSON to this path (bench harness reads it)

The summary line and --harness-summary are written by tests/conftest.py (harness/report.py):
that conftest is the one the pytest-xdist controller loads.
"""

from . import profiles
from .printer_bug import put_back


def pytest_configure(config):
    bug = config.getoption("printer_bug", default=False)
    profiles.select("thorough" if config.getoption("thorough", default=False) else "ci", count_only=bug)
    if bug:
        put_back()
