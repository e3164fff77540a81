"""The committed generated/ files match models/ and this generator (what `--check` verifies)."""

import pytest

from lg_test_support import MODEL_FILES, ROOT
from lagrange_gen.codegen.generated_files import is_current


@pytest.mark.parametrize("model_file", MODEL_FILES, ids=lambda p: p.stem)
def test_generated_file_is_current(model_file):
    target, current = is_current(model_file, ROOT / "generated")
    assert current, f"{target} is missing or stale: run `make generate` (lagrange-gen models/*.py)"
