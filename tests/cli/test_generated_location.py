"""Where generated modules go by default: one place per model file whatever the working
directory is (beside the folder of a project's models/, else beside the model file), -o and
out_dir= to choose another, and a folder that cannot be written names both."""

import os
import re
from pathlib import Path

import numpy as np
import pytest

import lagrange_gen as lg
from lagrange_gen.cli.main import main
from lagrange_gen.codegen.generated_files import generate_model
from lagrange_gen.codegen.keys import default_generated_dir, regeneration_command

ROOT = Path(__file__).resolve().parents[2]
MODEL = '''
from lagrange_gen import Model, coordinates, parameters

x = coordinates("x")
k = parameters("k", defaults=4.0)
model = Model("where_osc", coords=[x], T=x.d**2 / 2, V=k * x**2 / 2)
'''


@pytest.fixture
def project(tmp_path):
    (tmp_path / "models").mkdir()
    (tmp_path / "models" / "where_osc.py").write_text(MODEL)
    (tmp_path / "elsewhere").mkdir()
    return tmp_path


def test_the_repository_layout_is_unchanged(monkeypatch):
    monkeypatch.chdir(ROOT)
    assert default_generated_dir("models/cart_pendulum.py") == Path("generated")
    assert regeneration_command("models/cart_pendulum.py") == "lagrange-gen models/cart_pendulum.py"


def test_the_default_does_not_depend_on_the_working_directory(project, monkeypatch):
    want = (project / "generated").resolve()
    for cwd, path in ((project, "models/where_osc.py"),
                      (project / "elsewhere", "../models/where_osc.py"),
                      (project / "models", "where_osc.py")):
        monkeypatch.chdir(cwd)
        assert Path(default_generated_dir(path)).resolve() == want
    loose = project / "elsewhere" / "loose.py"
    want_loose = (project / "elsewhere" / "generated").resolve()
    assert Path(default_generated_dir(loose)).resolve() == want_loose


def test_the_cli_from_another_folder_finds_the_same_module(project, monkeypatch, capsys):
    monkeypatch.chdir(project)
    assert main(["models/where_osc.py", "--methods", "rk4"]) == 0
    assert "written" in capsys.readouterr().out
    monkeypatch.chdir(project / "elsewhere")
    assert main(["../models/where_osc.py", "--methods", "rk4"]) == 0
    assert "generated/where_osc.py is current" in capsys.readouterr().out
    assert main(["--check", "../models/where_osc.py", "--methods", "rk4"]) == 0
    assert not (project / "elsewhere" / "generated").exists()
    # simulate from there too: no second generated/ (the module there has rk4)
    assert main(["simulate", "../models/where_osc.py", "--method", "rk4", "--q0", "1",
                 "--t-end", "0.1", "--h", "0.01"]) == 0
    assert not (project / "elsewhere" / "generated").exists()
    assert sorted(p.name for p in (project / "generated").glob("*.py")) == ["where_osc.py"]


def test_an_ensemble_from_another_folder_uses_the_same_place(project, monkeypatch):
    generate_model(project / "models" / "where_osc.py", project / "generated", methods=["rk4"])
    monkeypatch.chdir(project / "elsewhere")
    ens = lg.ensemble("../models/where_osc.py", "rk4", q0=[[1.0], [0.5]], t_end=0.5, h=0.01)
    np.testing.assert_allclose(ens.q[:, -1, 0], [np.cos(1.0), 0.5 * np.cos(1.0)], atol=1e-6)
    assert not (project / "elsewhere" / "generated").exists()


def test_load_and_simulate_from_another_folder_use_the_same_place(project, monkeypatch):
    """lg.load and lg.simulate on a model file: the module goes to the model's own place from
    any working directory (it went to ./generated, a second copy, before)."""
    monkeypatch.chdir(project / "elsewhere")
    module = lg.load("../models/where_osc.py", methods=["rk4"])
    assert Path(module.__file__).resolve() == (project / "generated" / "where_osc.py").resolve()
    traj = lg.simulate("../models/where_osc.py", "rk4", q0=[1.0], t_end=0.5, h=0.01)
    assert traj.q[-1, 0] == pytest.approx(np.cos(1.0), abs=1e-6)
    assert not (project / "elsewhere" / "generated").exists()


def test_o_chooses_another_folder(project, monkeypatch, capsys):
    monkeypatch.chdir(project / "elsewhere")
    assert main(["../models/where_osc.py", "--methods", "rk4", "-o", "mine"]) == 0
    assert (project / "elsewhere" / "mine" / "where_osc.py").is_file()
    assert not (project / "generated").exists()


def test_an_unwritable_folder_names_o_and_out_dir(project, capsys):
    blocker = project / "generated"
    blocker.write_text("a file where the folder would be")
    assert main([str(project / "models" / "where_osc.py")]) != 0
    err = capsys.readouterr().err
    assert "cannot write generated files here" in err and "-o DIR" in err and "out_dir=" in err
    # one line, besides the progress lines of a stage that outlasts PROGRESS_AFTER on a busy
    # machine ("derive running (2 s)", "derive done in 2.3 s")
    progress = re.compile(r"lagrange-gen: .*: \w[\w ]* (running \(\d+ s\).*|done in [\d.]+ s)$")
    lines = [line for line in err.strip().splitlines() if not progress.match(line)]
    assert len(lines) == 1, err
