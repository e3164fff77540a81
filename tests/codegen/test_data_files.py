"""A model file that reads a data file (its parameters from JSON): the files a model read are
recorded at generation, so that a changed data file is seen by load, simulate and a direct
import, as ``--check`` sees it (issue 34, item 2)."""

import json
import os

import pytest

import lagrange_gen as lg
from lagrange_gen import StaleModuleError
from lagrange_gen.cli.main import main
from lagrange_gen.codegen import generate_model
from lagrange_gen.run.loader import import_generated

MODEL = '''
import json
from lagrange_gen import Model, coordinates, parameters

x = coordinates("x")
data = json.load(open("pend.json"))     # relative to the working directory, as users write it
k = parameters("k", defaults=data["k"])
model = Model("dep_osc", coords=[x], T=x.d**2 / 2, V=k * x**2 / 2)
'''


@pytest.fixture
def project(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "dep_osc.py").write_text(MODEL)
    (tmp_path / "pend.json").write_text(json.dumps({"k": 1.0}))
    return tmp_path


def _change_data(project, k):
    path = project / "pend.json"
    before = path.stat().st_mtime_ns
    path.write_text(json.dumps({"k": k}))
    os.utime(path, ns=(before + 10**9, before + 10**9))   # a new mtime even on coarse clocks


def test_simulate_of_the_model_file_sees_a_changed_data_file(project):
    run = dict(method="rk4", q0=[1.0], t_end=1.0, h=0.01, out_dir="gen")
    old = lg.simulate("dep_osc.py", **run).q[-1, 0]
    _change_data(project, 9.0)
    new = lg.simulate("dep_osc.py", **run).q[-1, 0]
    assert new == pytest.approx(1.0 * __import__("math").cos(3.0), abs=1e-6)
    assert old != pytest.approx(new, abs=1e-3)


def test_import_after_a_data_change_is_refused_naming_the_file(project):
    path = generate_model(project / "dep_osc.py", project / "gen", methods=["rk4"]).path
    import_generated(path)
    _change_data(project, 4.0)
    with pytest.raises(StaleModuleError, match=r"pend\.json changed since .*run lagrange-gen"):
        import_generated(path)


def test_unchanged_data_with_a_new_mtime_is_still_current(project):
    path = generate_model(project / "dep_osc.py", project / "gen", methods=["rk4"]).path
    _change_data(project, 1.0)
    assert import_generated(path).DEFAULT_PARAMS[0] == 1.0


def test_cli_simulate_prints_the_new_answer(project, capsys):
    args = ["simulate", "dep_osc.py", "--gen-dir", "gen", "--method", "rk4", "--q0", "1", "--t-end", "1",
            "--h", "0.01"]
    assert main(args) == 0
    first = capsys.readouterr().out
    _change_data(project, 9.0)
    assert main(args) == 0
    second = capsys.readouterr().out
    assert first != second and "-0.98999" in second
