"""Helpers for the nonsmooth tests (no conftest.py here: pytest would shadow the top-level one)."""

from pathlib import Path

import numpy as np
import pytest

from lagrange_gen.codegen import generate_model
from lagrange_gen.run.loader import import_generated

MODELS = Path(__file__).resolve().parents[2] / "models"
_cache = {}


@pytest.fixture(scope="session")
def ns_model(tmp_path_factory):
    """stem -> generated module (generated once per session into a temp dir)."""
    def get(stem, **options):
        key = (stem, tuple(sorted(options.items())))
        if key not in _cache:
            out = tmp_path_factory.mktemp("ns_gen")
            _cache[key] = import_generated(generate_model(MODELS / f"{stem}.py", out, options=options).path)
        return _cache[key]
    return get


def forcing(traj, f, omega, kind="cos"):
    """F(t) (S,) of a harmonic forcing f cos(omega t) or f sin(omega t)."""
    return f * (np.cos(omega * traj.t) if kind == "cos" else np.sin(omega * traj.t))
