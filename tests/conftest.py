"""Shared fixtures: every model in models/ is generated once per session into a temp dir."""

from pathlib import Path

import pytest

from lagrange_gen import load_model
from lagrange_gen.codegen import generate_model
from lagrange_gen.derive import derive
from lagrange_gen.loader import import_generated

ROOT = Path(__file__).resolve().parent.parent
MODELS_DIR = ROOT / "models"
MODEL_FILES = sorted(MODELS_DIR.glob("*.py"))


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
