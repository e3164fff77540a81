"""The explicit-time tests generate each model once per session (one directory), so a method's
glue compiled by one test module is loaded from numba's cache by the next."""

import pytest

from time_util import HERE, ROOT, generate


@pytest.fixture(scope="session")
def time_module(tmp_path_factory):
    """Return a function: model stem (tests/time/models/ first, then models/) -> module."""
    out, cache = tmp_path_factory.mktemp("time_generated"), {}

    def get(stem):
        if stem not in cache:
            path = HERE / "models" / f"{stem}.py"
            cache[stem] = generate(path if path.is_file() else ROOT / "models" / f"{stem}.py", out)
        return cache[stem]
    return get
