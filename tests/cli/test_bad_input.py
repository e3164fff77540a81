"""Bad input: one clear line naming the problem, non-zero exit, previous generated file intact."""

import shutil
import textwrap

import pytest

from lg_test_support import MODELS_DIR
from lagrange_gen.cli.main import main

HEADER = "import sympy as sp\nfrom lagrange_gen import Model, coordinates, parameters, t\n"
GOOD = HEADER + textwrap.dedent("""
    x = coordinates("x")
    m, k = parameters("m k", defaults=(1.0, 2.0))
    model = Model("spring", coords=[x], T=m * x.d**2 / 2, V=k * x**2 / 2)
""")

CASES = {
    "syntax": ("model = (", r"spring\.py:1: not valid Python"),
    "raises": (HEADER + "x = coordinates('x')\nraise RuntimeError('boom')\n", r"spring\.py:4: raised RuntimeError: boom"),
    "no_model": (HEADER + "x = 1\n", r"defines no Model"),
    "free_symbol": (GOOD.replace("V=k * x**2 / 2", "V=sp.Symbol('kappa') * x**2"),
                    r"V uses symbol\(s\) kappa that are neither"),
    "not_quadratic": (GOOD.replace("T=m * x.d**2 / 2", "T=m * x.d**4"), r"T is not quadratic in the velocities"),
    "not_definite": (GOOD.replace("T=m * x.d**2 / 2", "T=-m * x.d**2 / 2"),
                     r"not positive definite at x=.*x\.d"),
    "velocity_constraint": (GOOD.replace("V=k * x**2 / 2)", "V=k * x**2 / 2, constraints=[x.d - 1])"),
                            r"constraint 0 \(x_dot - 1\) depends on x_dot"),
    "duplicate": (GOOD.replace('parameters("m k"', 'parameters("m x"'),
                  r"duplicate name 'x'"),
    "bad_name": (GOOD.replace('coordinates("x")', 'coordinates("lambda")'), r"not a valid Python identifier"),
}


@pytest.fixture
def workspace(tmp_path):
    """A models dir with a good model already generated into out/."""
    model = tmp_path / "spring.py"
    model.write_text(GOOD)
    out = tmp_path / "out"
    assert main([str(model), "-o", str(out)]) == 0
    return model, out, (out / "spring.py").read_bytes()


@pytest.mark.parametrize("case", sorted(CASES))
def test_bad_model_one_line_nonzero_previous_file_kept(workspace, capsys, case):
    model, out, before = workspace
    capsys.readouterr()
    source, pattern = CASES[case]
    model.write_text(source)
    assert main([str(model), "-o", str(out)]) != 0
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1, err
    assert str(model) in err or "model spring" in err
    import re
    assert re.search(pattern, err), err
    assert (out / "spring.py").read_bytes() == before
    assert sorted(p.name for p in out.iterdir() if not p.name.startswith("__")) == ["spring.py"]


def test_missing_and_non_python_files(tmp_path, capsys):
    assert main([str(tmp_path / "nope.py")]) != 0
    assert "nope.py: no such model file" in capsys.readouterr().err
    txt = tmp_path / "model.txt"
    txt.write_text("hello")
    assert main([str(txt)]) != 0
    assert "must be a Python file" in capsys.readouterr().err


def test_unwritable_output_directory(workspace, capsys):
    model, out, before = workspace
    blocker = out.parent / "blocker"
    blocker.write_text("a file, not a directory")
    assert main([str(model), "-o", str(blocker / "sub")]) != 0
    err = capsys.readouterr().err
    assert "cannot write generated files here" in err and len(err.strip().splitlines()) == 1
    assert (out / "spring.py").read_bytes() == before


def test_check_reports_missing_and_stale(workspace, tmp_path, capsys):
    model, out, _ = workspace
    assert main(["--check", str(model), "-o", str(out)]) == 0
    model.write_text(GOOD.replace("2.0", "3.0"))
    assert main(["--check", str(model), "-o", str(out)]) == 1
    assert "stale" in capsys.readouterr().out
    assert main(["--check", str(model), "-o", str(tmp_path / "empty")]) == 1
    assert "missing" in capsys.readouterr().out


def test_parameter_without_value(tmp_path):
    from lagrange_gen import SimulationError
    from lagrange_gen.codegen import generate_model
    from lagrange_gen.run.loader import import_generated
    model = tmp_path / "spring.py"
    model.write_text(GOOD.replace("defaults=(1.0, 2.0)", "defaults={'m': 1.0}"))
    mod = import_generated(generate_model(model, tmp_path / "out").path)
    with pytest.raises(SimulationError, match=r"parameter\(s\) k have no value"):
        mod.accelerations([0.1], [0.0])
    assert mod.accelerations([0.1], [0.0], params={"k": 4.0})[0] == pytest.approx(-0.4)


def test_several_models_and_dynamicsymbols(tmp_path, capsys):
    ds = tmp_path / "ds.py"
    ds.write_text(textwrap.dedent("""
        import sympy as sp
        from sympy.physics.mechanics import dynamicsymbols
        from lagrange_gen import Model, parameters
        q = dynamicsymbols("q")
        m, l, g = parameters("m l g", defaults=(1.0, 2.0, 9.81))
        model = Model("ds_pendulum", coords=[q], T=m * l**2 * q.diff()**2 / 2, V=-m * g * l * sp.cos(q))
    """))
    shutil.copy(MODELS_DIR / "cart_pendulum.py", tmp_path / "cart_pendulum.py")
    assert main([str(ds), str(tmp_path / "cart_pendulum.py"), "-o", str(tmp_path / "out")]) == 0
    from lagrange_gen.run.loader import import_generated
    mod = import_generated(tmp_path / "out" / "ds_pendulum.py")
    assert mod.COORDS == ("q",)
    assert mod.accelerations([0.5], [0.0])[0] == pytest.approx(-9.81 / 2.0 * __import__("math").sin(0.5))
