"""A model file may import a helper module beside it (as `python model.py` could): its folder is
on sys.path while it runs and only then, the helper is read afresh on every load, and a changed
helper makes the generated module stale as a changed data file does."""

import math
import os
import sys

import pytest

import lagrange_gen as lg
from lagrange_gen import StaleModuleError
from lagrange_gen.codegen import generate_model
from lagrange_gen.model.model_file import load_model
from lagrange_gen.run.loader import import_generated

MODEL = '''
from lagrange_gen import Model, coordinates, parameters
import helper_params

x = coordinates("x")
k = parameters("k", defaults=helper_params.K)
model = Model("helped_osc", coords=[x], T=x.d**2 / 2, V=k * x**2 / 2)
'''


@pytest.fixture
def project(tmp_path):
    folder = tmp_path / "models"
    folder.mkdir()
    (folder / "helped_osc.py").write_text(MODEL)
    (folder / "helper_params.py").write_text("K = 1.0\n")
    return folder


def _change_helper(folder, k):
    path = folder / "helper_params.py"
    before = path.stat().st_mtime_ns
    path.write_text(f"K = {k!r}\n")
    os.utime(path, ns=(before + 10**9, before + 10**9))   # a new mtime even on coarse clocks


def test_a_model_file_imports_a_helper_beside_it_and_sys_path_is_restored(project):
    path_before, modules_before = list(sys.path), set(sys.modules)
    model = load_model(project / "helped_osc.py")
    assert model.params[0].default == 1.0
    assert sys.path == path_before
    assert "helper_params" not in set(sys.modules) - modules_before
    assert str((project / "helper_params.py").resolve()) in model.data_files


def test_the_helper_is_read_again_on_the_next_load(project):
    assert load_model(project / "helped_osc.py").params[0].default == 1.0
    _change_helper(project, 4.0)
    assert load_model(project / "helped_osc.py").params[0].default == 4.0


def test_a_changed_helper_makes_the_generated_module_stale(project, tmp_path):
    path = generate_model(project / "helped_osc.py", tmp_path / "gen", methods=["rk4"]).path
    import_generated(path)
    _change_helper(project, 4.0)
    with pytest.raises(StaleModuleError, match=r"helper_params\.py changed since"):
        import_generated(path)


def test_simulate_sees_the_changed_helper(project, tmp_path):
    run = dict(method="rk4", q0=[1.0], t_end=1.0, h=0.01, out_dir=tmp_path / "gen")
    first = lg.simulate(project / "helped_osc.py", **run).q[-1, 0]
    assert first == pytest.approx(math.cos(1.0), abs=1e-6)
    _change_helper(project, 9.0)
    second = lg.simulate(project / "helped_osc.py", **run).q[-1, 0]
    assert second == pytest.approx(math.cos(3.0), abs=1e-6)


def test_modules_below_the_folder_that_are_not_helpers_stay_imported(tmp_path):
    """A package installed below the model's folder (a virtual environment inside the project)
    is not a helper: it is neither recorded nor removed from sys.modules."""
    site = tmp_path / "venv" / "lib" / "site-packages"
    site.mkdir(parents=True)
    (site / "vendored_thing.py").write_text("K = 2.0\n")
    (tmp_path / "vendored_osc.py").write_text(MODEL.replace("helper_params", "vendored_thing")
                                              .replace("helped_osc", "vendored_osc"))
    sys.path.insert(0, str(site))
    try:
        model = load_model(tmp_path / "vendored_osc.py")
        assert model.params[0].default == 2.0
        assert "vendored_thing" in sys.modules
        assert not any("vendored_thing" in path for path in model.data_files)
    finally:
        sys.path.remove(str(site))
        sys.modules.pop("vendored_thing", None)
