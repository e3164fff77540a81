"""Everything a model file reads while it runs is an input of its generated module (issue 41 item
2): a Python file it exec()s as data, a helper module it imports from another folder through a
sys.path entry it adds. A change to one is seen alike by the import-time check, ``--check``,
``lg.load`` and ``simulate`` (keys.changed_input decides for all of them), and load regenerates
and gives the new numbers, in the same process too."""

import os
import sys
import textwrap

import pytest

import lagrange_gen as lg
from lagrange_gen import StaleModuleError
from lagrange_gen.cli.main import main
from lagrange_gen.model.model_file import load_model
from lagrange_gen.run.loader import import_generated

EXEC_MODEL = textwrap.dedent('''\
    from pathlib import Path
    from lagrange_gen import Model, coordinates, parameters

    data = {}
    exec((Path(__file__).parent.parent / "data" / "exec_params.py").read_text(), data)
    x = coordinates("x")
    k = parameters("k", defaults=(data["K"],))
    model = Model("exec_spring", coords=[x], T=x.d**2 / 2, V=data["C"] * k * x**2 / 2)
    ''')

PATH_MODEL = textwrap.dedent('''\
    import sys
    from pathlib import Path
    sys.path.insert(0, str(Path(__file__).parent.parent / "lib"))
    import far_helper
    from lagrange_gen import Model, coordinates, parameters

    x = coordinates("x")
    k = parameters("k", defaults=(far_helper.K,))
    model = Model("path_spring", coords=[x], T=x.d**2 / 2, V=far_helper.C * k * x**2 / 2)
    ''')


def _write(path, text):
    """Write ``text`` with an mtime a second later than before (coarse clocks)."""
    before = path.stat().st_mtime_ns if path.exists() else None
    path.write_text(text)
    if before is not None:
        os.utime(path, ns=(before + 10**9, before + 10**9))


@pytest.fixture
def exec_project(tmp_path):
    project = tmp_path / "exec"
    for folder in ("models", "data"):
        (project / folder).mkdir(parents=True)
    (project / "models" / "exec_spring.py").write_text(EXEC_MODEL)
    _write(project / "data" / "exec_params.py", "K = 1.0\nC = 2.0\n")
    return project


@pytest.fixture
def path_project(tmp_path):
    project = tmp_path / "path"
    for folder in ("models", "lib"):
        (project / folder).mkdir(parents=True)
    (project / "models" / "path_spring.py").write_text(PATH_MODEL)
    _write(project / "lib" / "far_helper.py", "K = 1.0\nC = 2.0\n")
    yield project
    sys.modules.pop("far_helper", None)


def test_an_execd_python_file_is_recorded(exec_project):
    model = load_model(exec_project / "models" / "exec_spring.py")
    assert str((exec_project / "data" / "exec_params.py").resolve()) in model.data_files


def test_a_helper_imported_from_another_folder_is_recorded_and_read_again(path_project):
    modules_before = set(sys.modules)
    model = load_model(path_project / "models" / "path_spring.py")
    assert str((path_project / "lib" / "far_helper.py").resolve()) in model.data_files
    assert "far_helper" not in set(sys.modules) - modules_before
    _write(path_project / "lib" / "far_helper.py", "K = 4.0\nC = 2.0\n")
    assert load_model(path_project / "models" / "path_spring.py").params[0].default == 4.0


def test_files_numpy_reads_are_recorded(tmp_path):
    import numpy as np
    np.save(tmp_path / "table.npy", np.array([1.5, 2.5]))
    np.savetxt(tmp_path / "table.csv", np.array([[3.0, 4.0]]), delimiter=",")
    (tmp_path / "np_spring.py").write_text(textwrap.dedent('''\
        from pathlib import Path
        import numpy as np
        from lagrange_gen import Model, coordinates, parameters
        here = Path(__file__).parent
        a = np.load(here / "table.npy")
        b = np.loadtxt(here / "table.csv", delimiter=",")
        x = coordinates("x")
        k = parameters("k", defaults=(float(a[0] + b[1]),))
        model = Model("np_spring", coords=[x], T=x.d**2 / 2, V=k * x**2 / 2)
        '''))
    model = load_model(tmp_path / "np_spring.py")
    assert model.params[0].default == 5.5
    assert {str((tmp_path / name).resolve()) for name in ("table.npy", "table.csv")} <= set(model.data_files)


@pytest.mark.parametrize("case", ["exec", "path"])
def test_load_check_and_import_see_a_changed_input(case, exec_project, path_project, capsys):
    project = exec_project if case == "exec" else path_project
    stem = f"{case}_spring"
    model = project / "models" / f"{stem}.py"
    changed = project / ("data" if case == "exec" else "lib") / (
        "exec_params.py" if case == "exec" else "far_helper.py")
    out = project / "gen"
    first = lg.load(model, out_dir=out, methods=["rk4"])
    assert first.DEFAULTS == (1.0,)
    assert "rhs[0] = -2.0*p_0*q_0" in (out / f"{stem}.py").read_text()      # C = 2
    assert main([str(model), "-o", str(out), "--methods", "rk4"]) == 0
    assert main(["--check", str(model), "-o", str(out), "--methods", "rk4"]) == 0
    capsys.readouterr()

    _write(changed, "K = 3.0\nC = 5.0\n")
    with pytest.raises(StaleModuleError, match=rf"{changed.name} changed since"):
        import_generated(out / f"{stem}.py")
    assert main(["--check", str(model), "-o", str(out), "--methods", "rk4"]) == 1
    line = capsys.readouterr().out.strip()
    assert "stale" in line and changed.name in line, line

    mod = lg.load(model, out_dir=out, methods=["rk4"])
    assert mod.DEFAULTS == (3.0,)
    assert "rhs[0] = -5.0*p_0*q_0" in (out / f"{stem}.py").read_text()      # C = 5
    assert main(["--check", str(model), "-o", str(out), "--methods", "rk4"]) == 0
