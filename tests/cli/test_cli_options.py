"""The command line as a user drives it (issue 16, item 6): --param with commas (the parser of
--freeze and --set), simulate --set, a model file with only build(), warnings as one line,
--keep for a constrained start, and several model files with bad ones among them."""

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from lagrange_gen.cli.main import main
from lagrange_gen.run.simulate import simulate

ROOT = Path(__file__).resolve().parents[2]
MODELS = ROOT / "models"
SPRING = textwrap.dedent("""
    import sympy as sp
    from lagrange_gen import Model, coordinates, parameters
    def build(k=2.0, name="spring"):
        x = coordinates("x")
        m, kk = parameters("m k", defaults=(1.0, float(k)))
        return Model(name, coords=[x], T=m * x.d**2 / 2, V=kk * x**2 / 2)
""")


def _final_q(out):
    line = next(line for line in out.splitlines() if line.startswith("final q = "))
    return np.array([float(x) for x in line.split("[")[1].split("]")[0].split(",")])


@pytest.fixture(scope="module")
def cart(generated):
    return generated("cart_pendulum")


def test_param_with_commas_equals_repeated_and_python(cart, capsys):
    base = ["simulate", cart.__file__, "--method", "rk4", "--h", "1e-2", "--t-end", "1",
            "--q0", "0.1", "0.5"]
    assert main(base + ["--param", "k=20,m=0.7"]) == 0
    commas = _final_q(capsys.readouterr().out)
    assert main(base + ["--param", "k=20", "--param", "m=0.7"]) == 0
    repeated = _final_q(capsys.readouterr().out)
    python = simulate(cart, "rk4", [0.1, 0.5], t_end=1, h=1e-2, params={"k": 20, "m": 0.7}).q[-1]
    default = simulate(cart, "rk4", [0.1, 0.5], t_end=1, h=1e-2).q[-1]
    np.testing.assert_allclose(commas, python, rtol=1e-8)
    np.testing.assert_array_equal(commas, repeated)
    assert np.abs(default - python).max() > 1e-3          # the parameters did change the run
    for bad, says in (("k=abc", "'abc' is not a number"), ("k", "expected NAME=VALUE"),
                      ("k=1,,m", "expected NAME=VALUE")):
        assert main(base + ["--param", bad]) == 2
        err = capsys.readouterr().err.strip()
        assert err.count("\n") == 0 and says in err and "--param" in err, err


def test_simulate_set_builds_the_family_member(tmp_path, capsys):
    code = main(["simulate", str(MODELS / "n_link_pendulum.py"), "--set", "n=2", "--method", "rk4",
                 "--h", "1e-3", "--t-end", "0.01", "--q0", "0.1", "0.2", "--gen-dir", str(tmp_path)])
    assert code == 0
    assert "model n_link_pendulum_2" in capsys.readouterr().out
    assert (tmp_path / "n_link_pendulum_2.py").is_file()
    generated_module = str(tmp_path / "n_link_pendulum_2.py")
    assert main(["simulate", generated_module, "--set", "n=3", "--h", "1e-3", "--t-end", "0.01"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "is a generated module: build options (n) apply to model files" in err


def test_file_with_only_build_uses_its_defaults(tmp_path, capsys):
    path = tmp_path / "spring_family.py"
    path.write_text(SPRING)
    assert main([str(path), "-o", str(tmp_path / "out")]) == 0
    text = (tmp_path / "out" / "spring.py").read_text()
    assert "DEFAULTS = (1.0, 2.0)" in text
    path.write_text(SPRING.replace("def build(k=2.0,", "def build(k,"))
    assert main([str(path), "-o", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "build() needs k" in err and "--set k=" in err


def _cli(*args, cwd):
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"))
    return subprocess.run([sys.executable, "-m", "lagrange_gen.cli", *map(str, args)], cwd=cwd,
                          env=env, capture_output=True, text=True, timeout=300)


def test_many_files_go_on_past_bad_ones_and_warnings_are_one_line(tmp_path):
    warn = (MODELS / "damped_oscillator.py").read_text().replace(
        "from lagrange_gen import", "import warnings\nwarnings.warn('careful: demo')\nfrom lagrange_gen import", 1)
    files = {"a_cart.py": (MODELS / "cart_pendulum.py").read_text(), "b_exits.py": "raise SystemExit(3)\n",
             "c_warns.py": warn, "d_nomodel.py": "x = 1\n", "e_spring.py": SPRING}
    for name, text in files.items():
        (tmp_path / name).write_text(text)
    result = _cli(*files, "-o", "out", cwd=tmp_path)
    assert result.returncode == 2, result.stderr
    written = sorted(p.name for p in (tmp_path / "out").glob("*.py"))
    assert written == ["cart_pendulum.py", "damped_oscillator.py", "spring.py"]
    err = result.stderr.strip().splitlines()
    assert "lagrange-gen: warning: careful: demo" in err
    assert err.index("lagrange-gen: warning: careful: demo") < len(err) - 1      # before the summary
    assert not any("warnings.warn" in line or "UserWarning" in line for line in err), err
    assert err[-1] == "lagrange-gen: 2 of 5 model files failed: b_exits.py, d_nomodel.py"
    assert sum(line.startswith("lagrange-gen: error:") for line in err) == 2


def test_keep_chooses_the_velocities_the_projection_keeps(tmp_path, capsys, generated):
    """Cartesian pendulum at q0 = (0.6, -0.8) (on the circle, J = (x, y)): v0 = (1, 1) is not
    tangent. Keeping y_dot = 1, J v = 0 gives x_dot = 0.8 / 0.6; keeping x_dot = 1, y_dot = 0.75;
    at q0 = (1, 0) (J = (1, 0)) keeping x_dot = 1 cannot be made tangent."""
    module = generated("cartesian_pendulum").__file__
    base = ["simulate", module, "--method", "rattle", "--h", "1e-3", "--t-end", "1e-3",
            "--v0", "1", "1"]
    cart = generated("cart_pendulum").__file__
    assert main(["simulate", cart, "--method", "rk4", "--h", "1e-2", "--t-end", "0.1", "--keep",
                 "x_dot"]) == 2
    assert "this model has no constraints" in capsys.readouterr().err
    for keep, v_start in (("y_dot", [0.8 / 0.6, 1.0]), ("x", [1.0, 0.75])):
        out = tmp_path / f"keep_{keep}.npz"
        assert main(base + ["--q0", "0.6", "-0.8", "--keep", keep, "--out", str(out)]) == 0
        np.testing.assert_allclose(np.load(out)["v"][0], v_start, rtol=1e-12)
        err = capsys.readouterr().err
        assert f"keeping {keep if keep.endswith('_dot') else keep + '_dot'}" in err
    for q0, keep, says in ((["1", "0"], "x_dot", "keeping x_dot at v0 leaves J v = 0 unsolvable"),
                           (["0.6", "-0.8"], "z_dot", "keep 'z_dot' is not a velocity")):
        assert main(base + ["--q0", *q0, "--keep", keep]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and says in err[0], err
    with pytest.warns(UserWarning, match="keep= / --keep names velocities"):
        default = simulate(module, "rattle", [0.6, -0.8], [1, 1], t_end=1e-3, h=1e-3)
    # without keep: the closest tangent velocity (H = I), v0 - (J v0) J^T / |J|^2 = (1.12, 0.84)
    np.testing.assert_allclose(default.v[0], [1.12, 0.84], rtol=1e-12)
