"""The test model of this directory, generated once per session (a fixture the tests import:
no conftest.py here, whose name would shadow tests/conftest.py for `from lg_test_support import ...`)."""

from pathlib import Path

import pytest

from lagrange_gen.codegen import generate_model
from lagrange_gen.run.loader import import_generated

HERE = Path(__file__).resolve().parent


@pytest.fixture(scope="session")
def torque_pendulum(gen_dir):
    """tests/control/torque_pendulum.py: an input without default, two outputs."""
    return import_generated(generate_model(HERE / "torque_pendulum.py", gen_dir).path)


@pytest.fixture(scope="session")
def modulated_pendulum(gen_dir):
    """tests/control/modulated_pendulum.py: torque_pendulum with H(q, t)."""
    return import_generated(generate_model(HERE / "modulated_pendulum.py", gen_dir).path)
