"""The simulate() driver, its Trajectory and the `lagrange-gen simulate` subcommand."""

import argparse
import re
from pathlib import Path

import numpy as np
import pytest

import lagrange_gen.run.simulate as simulate_module
from lagrange_gen.cli.main import main
from lagrange_gen.cli.simulate import add_parser, run as run_cli
from lagrange_gen.run.loader import import_generated
from lagrange_gen.run.simulate import simulate


MODELS_DIR = Path(__file__).resolve().parent.parent / "models"
Q0, V0 = [0.1, 0.5], [0.0, 0.2]


@pytest.fixture(scope="module")
def cart(generated):
    return generated("cart_pendulum")


def test_saved_rows_times_and_energy(cart):
    traj = simulate(cart, "rk4", Q0, V0, t_end=1.0, h=0.01, save_every=7)
    # 100 steps: rows after steps 0, 7, ..., 98 and the final state after step 100
    assert traj.n_steps == 100 and len(traj.t) == 100 // 7 + 2
    np.testing.assert_allclose(traj.t[:-1], 0.07 * np.arange(15), rtol=0, atol=1e-12)
    assert traj.t[-1] == pytest.approx(1.0)
    every = simulate(cart, "rk4", Q0, V0, t_end=1.0, h=0.01)
    np.testing.assert_array_equal(traj.q[-1], every.q[-1])
    np.testing.assert_array_equal(traj.q[:-1], every.q[:-1:7])
    p = np.array(list(traj.params.values()))
    for i in (0, 5, -1):
        assert traj.energy[i] == pytest.approx(cart.energy(traj.q[i], traj.v[i], traj.t[i], p),
                                               rel=1e-14)


def test_t_end_not_a_multiple_of_h_is_rounded_up_to_a_whole_step(cart):
    traj = simulate(cart, "rk4", Q0, V0, t_end=0.105, h=0.01)
    assert traj.n_steps == 11 and traj.t[-1] == pytest.approx(0.11)


def test_chunked_run_equals_one_call(cart, monkeypatch):
    whole = {m: simulate(cart, m, Q0, V0, t_end=1.0, h=0.01, save_every=3)
             for m in ("rk4", "midpoint")}
    import lagrange_gen.run.fixed_driver as fixed_run      # where the chunk size lives
    monkeypatch.setattr(fixed_run, "CHUNK_STEPS", 9)
    for method, ref in whole.items():
        chunked = simulate(cart, method, Q0, V0, t_end=1.0, h=0.01, save_every=3)
        np.testing.assert_allclose(chunked.q, ref.q, rtol=0, atol=1e-13)
        np.testing.assert_allclose(chunked.v, ref.v, rtol=0, atol=1e-13)
        np.testing.assert_array_equal(chunked.t, ref.t)
        assert abs(chunked.newton_iters.sum() - ref.newton_iters.sum()) <= 2


def test_newton_statistics_are_recorded(cart):
    traj = simulate(cart, "midpoint", Q0, V0, t_end=0.5, h=0.01, save_every=5)
    assert traj.newton_iters[0] == 0
    assert np.all(traj.newton_iters[1:] >= 5)          # at least one iteration per step
    assert np.all(traj.newton_residual[1:] < 1e-6)


def test_params_override_defaults(cart):
    soft = simulate(cart, "rk4", Q0, V0, t_end=1.0, h=0.01)
    stiff = simulate(cart, "rk4", Q0, V0, t_end=1.0, h=0.01, params={"k": 40.0})
    assert stiff.params["k"] == 40.0 and soft.params["k"] != 40.0
    assert np.abs(stiff.q[-1] - soft.q[-1]).max() > 1e-3


def test_writers(cart, tmp_path):
    traj = simulate(cart, "verlet", Q0, V0, t_end=1.0, h=0.01, save_every=10)
    traj.to_npz(tmp_path / "out" / "t.npz")
    data = np.load(tmp_path / "out" / "t.npz")
    np.testing.assert_array_equal(data["q"], traj.q)
    assert str(data["method"]) == "verlet" and list(data["coords"]) == ["x", "theta"]
    traj.to_csv(tmp_path / "t.csv")
    lines = (tmp_path / "t.csv").read_text().splitlines()
    assert lines[0] == "t,x,theta,x_dot,theta_dot,energy,newton_iters"
    assert len(lines) == len(traj.t) + 1
    np.testing.assert_allclose(np.loadtxt(tmp_path / "t.csv", delimiter=",", skiprows=1)[:, 1:3],
                               traj.q, rtol=1e-15)
    traj.plot(tmp_path / "t.png")
    assert (tmp_path / "t.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_progress_bar_goes_to_stderr(cart, capsys):
    simulate(cart, "rk4", Q0, V0, t_end=0.1, h=0.01, progress=True)
    err = capsys.readouterr().err
    assert "100%" in err and "#" in err


def test_model_file_is_generated_when_missing(tmp_path):
    traj = simulate(MODELS_DIR / "cart_pendulum.py", "rk4", Q0, V0, t_end=0.1, h=0.01,
                    out_dir=tmp_path)
    assert (tmp_path / "cart_pendulum.py").is_file() and traj.model == "cart_pendulum"


def test_cli_subcommand_summary_and_files(cart, tmp_path, capsys):
    parser = argparse.ArgumentParser()
    add_parser(parser.add_subparsers(dest="command"))
    args = parser.parse_args(["simulate", cart.__file__, "--method", "midpoint", "--h", "1e-2",
                              "--t-end", "1", "--q0", "0.1", "0.5", "--v0", "0", "0.2",
                              "--param", "k=20", "--save-every", "10",
                              "--out", str(tmp_path / "t.csv"), "--plot", str(tmp_path / "t.png")])
    assert run_cli(args) == 0
    out = capsys.readouterr().out
    assert "method midpoint" in out and "100 steps" in out and "max |E - E0|" in out
    assert (tmp_path / "t.csv").is_file() and (tmp_path / "t.png").is_file()


def test_cli_errors_are_one_line(cart, capsys):
    code = main(["simulate", cart.__file__, "--method", "rk4", "--h", "0", "--t-end", "1"])
    err = capsys.readouterr().err.strip()
    assert code != 0 and "h must be > 0" in err and "\n" not in err
    code = main(["simulate", cart.__file__, "--h", "0.1", "--t-end", "1", "--param", "k"])
    assert code != 0 and "expected NAME=VALUE" in capsys.readouterr().err


# Output paths (issue 11): checked before the run; a write that still fails loses nothing.

def _simulate_cli(cart, capsys, *extra):
    """(exit code, stdout, stderr) of `lagrange-gen simulate` on cart; stderr without the
    compile notice (jit.compile_notice), which a first run on a busy machine may add."""
    code = main(["simulate", cart.__file__, "--method", "rk4", "--h", "1e-2", "--t-end", "1",
                 "--q0", "0.1", "0.5", *map(str, extra)])
    out, err = capsys.readouterr()
    err = "".join(line for line in err.splitlines(keepends=True)
                  if not line.startswith("lagrange-gen: compiling "))
    return code, out, err


@pytest.mark.parametrize("option, path, fragment", [
    ("--out", "/proc/traj.npz", "cannot create files in /proc"),
    ("--out", "{tmp}/afile/x.csv", "afile is not a directory"),
    ("--out", "{tmp}/traj.txt", "use a .npz or .csv file name"),
    ("--out", "{tmp}", "use a .npz or .csv file name"),
    ("--plot", "{tmp}/traj.npz", "use a .png or .pdf or .svg file name"),
    ("--plot", "{tmp}/afile/p.png", "afile is not a directory"),
])
def test_output_paths_are_checked_before_the_run(cart, capsys, tmp_path, option, path, fragment):
    (tmp_path / "afile").write_text("a file, not a directory")
    code, out, err = _simulate_cli(cart, capsys, option, path.format(tmp=tmp_path))
    assert code != 0 and "Traceback" not in err and len(err.strip().splitlines()) == 1
    assert fragment in err and option in err
    assert "steps to t" not in out          # refused before integrating


def test_failed_write_after_the_run_saves_the_trajectory_elsewhere(cart, capsys, tmp_path,
                                                                   monkeypatch):
    def disk_full(self, path):
        raise OSError(28, "No space left on device")
    monkeypatch.setattr(simulate_module.Trajectory, "to_csv", disk_full)
    code, out, err = _simulate_cli(cart, capsys, "--out", tmp_path / "t.csv")
    assert code != 0 and "Traceback" not in err and len(err.strip().splitlines()) == 1
    assert "No space left on device" in err and "steps to t = 1" in out
    rescued = Path(re.search(r"saved to (\S+\.npz) instead", err).group(1))
    reference = simulate(cart, "rk4", [0.1, 0.5], None, t_end=1.0, h=1e-2)
    np.testing.assert_array_equal(np.load(rescued)["q"], reference.q)
    rescued.unlink()


def test_failed_plot_after_the_run_names_the_written_trajectory(cart, capsys, tmp_path,
                                                                monkeypatch):
    def broken(self, path):
        raise RuntimeError("renderer crashed")
    monkeypatch.setattr(simulate_module.Trajectory, "plot", broken)
    code, out, err = _simulate_cli(cart, capsys, "--out", tmp_path / "t.npz",
                                   "--plot", tmp_path / "t.png")
    assert code != 0 and "Traceback" not in err and "renderer crashed" in err
    assert f"the trajectory is in {tmp_path / 't.npz'}" in err
    assert np.load(tmp_path / "t.npz")["q"].shape == (101, 2)


def test_model_file_with_elements_runs_implicit_euler_in_a_fresh_directory(tmp_path):
    """implicit_euler on a model with elements runs nonsmooth_euler: loading the model file for
    it must give a module that has the method that actually runs."""
    model = MODELS_DIR / "prandtl.py"
    traj = simulate(model, "implicit_euler", t_end=0.01, h=1e-3, out_dir=tmp_path)
    assert traj.method == "nonsmooth_euler" and len(traj.t) == 11


def test_module_generated_without_the_method_gets_it_added(tmp_path, capsys):
    model = MODELS_DIR / "damped_oscillator.py"
    assert main([str(model), "-o", str(tmp_path), "--methods", "rk4"]) == 0
    traj = simulate(model, "verlet", q0=[1.0], t_end=0.01, h=1e-3, out_dir=tmp_path)
    assert len(traj.t) == 11
    text = (tmp_path / "damped_oscillator.py").read_text()
    assert "METHODS = ('verlet', 'rk4')" in text
    assert hasattr(import_generated(tmp_path / "damped_oscillator.py"), "run_verlet")
