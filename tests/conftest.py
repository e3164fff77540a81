"""Shared fixtures: every model in models/ is generated once per session into a temp dir."""

import json
import os

import pytest

from lagrange_gen import load_model
from lagrange_gen.codegen import generate_model
from lagrange_gen.derive import derive
from lagrange_gen.run.loader import import_generated
from lg_test_support import MODELS_DIR

# A first run of a method compiles in the foreground and leaves no compile process behind
# (lagrange_gen.jit.first_run): which code a test runs must not depend on the order in which
# tests fill numba's cache. tests/test_interpreted.py turns both on where it tests them.
os.environ.setdefault("LAGRANGE_GEN_BACKGROUND_COMPILE", "0")
os.environ.setdefault("LAGRANGE_GEN_INTERPRETED", "0")

def pytest_addoption(parser):
    """Options of the differential harness (tests/harness/conftest.py says what they do); here,
    in the root conftest, so that ``pytest --thorough`` works from the repository root too."""
    group = parser.getgroup("harness", "differential harness (tests/harness)")
    group.addoption("--thorough", action="store_true", help="draw hundreds of models (thorough profile)")
    group.addoption("--printer-bug", action="store_true",
                    help="put the old a/x**2 -> a/x*x printer bug back and count failing examples")
    group.addoption("--harness-summary", metavar="PATH", help="write the harness counts as JSON here")
    parser.addoption("--all-robots", action="store_true",
                     help="tests/interop/test_pinocchio_urdf.py: every URDF of example-robot-data, "
                          "not a few")


@pytest.fixture(scope="session")
def gen_dir(tmp_path_factory):
    return tmp_path_factory.mktemp("generated")


@pytest.fixture(scope="session")
def generated(gen_dir):
    """Return a function: model file stem -> imported generated module (generated once)."""
    cache = {}

    def get(stem, **options):
        key = (stem, tuple(sorted(options.items())))
        if key not in cache:
            result = generate_model(MODELS_DIR / f"{stem}.py", gen_dir, options=options)
            cache[key] = import_generated(result.path)
        return cache[key]
    return get


@pytest.fixture(scope="session")
def derived():
    """Return a function: model file stem -> Dynamics (derived once)."""
    cache = {}

    def get(stem):
        if stem not in cache:
            cache[stem] = derive(load_model(MODELS_DIR / f"{stem}.py"))
        return cache[stem]
    return get


# The differential harness's report (tests/harness): here, not in tests/harness/conftest.py,
# because this is the conftest the pytest-xdist controller loads.

def pytest_sessionfinish(session):
    """On a pytest-xdist worker: hand this worker's harness counts to the controller."""
    from harness import report
    workeroutput = getattr(session.config, "workeroutput", None)
    if workeroutput is not None:
        workeroutput["harness"] = report.worker_counts()


@pytest.hookimpl(optionalhook=True)
def pytest_testnodedown(node, error):
    """On the xdist controller: add a finished worker's harness counts."""
    from harness import report
    counts = getattr(node, "workeroutput", {}).get("harness")
    if counts:
        report.add_worker_counts(counts)


def pytest_terminal_summary(terminalreporter, config):
    from harness import report
    s = report.summary()
    path = config.getoption("harness_summary", default=None)
    if path:
        with open(path, "w") as fh:
            json.dump(s, fh, indent=1, sort_keys=True)
    if s["models"]:
        bug = config.getoption("printer_bug", default=False)
        terminalreporter.write_line(
            f"harness ({s['profile']}): {s['models']} models drawn, {s['kernel_checks']} kernel checks, "
            f"{len(s['kinds'])} kernel kinds" + (f", {s['failed_models']} models failed (--printer-bug)" if bug else ""))
