"""Importing a generated module directly (not through lagrange_gen.load) after its model file
changed must not silently run the old kernels: the model text is not in the generated file (a
comment edit must leave it byte-identical), so the import compares it with the record that
generation leaves next to numba's cache."""

import shutil

import pytest

from lg_test_support import MODELS_DIR
from lagrange_gen import StaleModuleError
from lagrange_gen.cli.main import main
from lagrange_gen.codegen import generate_model
from lagrange_gen.run.loader import import_generated


@pytest.fixture
def copy(tmp_path):
    model = tmp_path / "models" / "osc.py"
    model.parent.mkdir()
    shutil.copy(MODELS_DIR / "damped_oscillator.py", model)
    return model, tmp_path / "gen"


def test_direct_import_after_a_model_change_is_refused(copy):
    model, out = copy
    path = generate_model(model, out, methods=["rk4"]).path
    import_generated(path)
    model.write_text(model.read_text().replace("1.0", "3.0", 1))
    with pytest.raises(StaleModuleError, match=r"osc\.py changed since .*run lagrange-gen"):
        import_generated(path)


def test_comment_edit_then_regeneration_leaves_the_file_and_imports(copy):
    model, out = copy
    path = generate_model(model, out, methods=["rk4"]).path
    before = path.read_bytes()
    model.write_text("# a comment added by the user\n" + model.read_text())
    with pytest.raises(StaleModuleError, match="changed since"):
        import_generated(path)
    assert main([str(model), "-o", str(out), "--methods", "rk4"]) == 0
    assert path.read_bytes() == before
    assert import_generated(path).NAME == "damped_oscillator"
