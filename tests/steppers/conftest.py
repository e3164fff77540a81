"""Fixtures of the stepper tests: each model is generated once per session into a temp dir."""

import pytest

from lagrange_gen.codegen import generate_model
from lagrange_gen.loader import import_generated

from stepper_util import MODEL_FILES


@pytest.fixture(scope="session")
def stepper_gen_dir(tmp_path_factory):
    return tmp_path_factory.mktemp("stepper_models")


@pytest.fixture(scope="session")
def model(stepper_gen_dir):
    """Return a function: model name (see MODEL_FILES) -> imported generated module.

    Modules carry the glue of every method; numba compiles a run_<method> on its first call only.
    """
    cache = {}

    def get(name):
        if name not in cache:
            result = generate_model(MODEL_FILES[name], stepper_gen_dir)
            cache[name] = import_generated(result.path)
        return cache[name]
    return get
