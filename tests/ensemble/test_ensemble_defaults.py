"""What an ensemble does without being told: save_every chosen so that the saved output stays
under a budget (with one line saying what was chosen and how to choose), a compile notice when
the ensemble glue compiles, compile time reported apart from stepping, and the result as a tidy
pandas frame."""

from pathlib import Path

import numpy as np
import pytest

import lagrange_gen as lg
from lagrange_gen.cli.main import main
from lagrange_gen.jit import compile_notice
from lagrange_gen.run import ensemble as ensemble_module
from lagrange_gen.run.ensemble import ensemble_bytes

ROOT = Path(__file__).resolve().parents[2]
DAMPED = ROOT / "generated" / "damped_oscillator.py"
STEPS = 400


def _ensemble(**options):
    # harmonic members (b = 0): x = x0 cos(t / sqrt(m c)) with x0 = 1
    c = np.array([0.5, 1.0, 2.0])
    return lg.ensemble(DAMPED, "rk4", q0=[1.0], params={"c": c, "m": 1.0, "b": 0.0},
                       t_end=STEPS * 0.01, h=0.01, **options)


def test_the_default_save_every_keeps_the_output_under_the_budget(monkeypatch):
    budget = 20_000
    monkeypatch.setattr(ensemble_module, "OUTPUT_BUDGET_BYTES", budget)
    with pytest.warns(UserWarning, match=r"saving every step would hold .* save_every=\d+ "
                                         r"\(\d+ states.*pass save_every="):
        ens = _ensemble()
    n, n_saved, M = 1, 0, 3
    k = round((ens.t[1] - ens.t[0]) / 0.01)
    assert k > 1 and ensemble_bytes(M, len(ens.t), n, n_saved, 3) <= budget
    # the smallest such save_every: one less would not fit
    rows = STEPS // (k - 1) + 1 + (1 if STEPS % (k - 1) else 0)
    assert ensemble_bytes(M, rows, n, n_saved, 3) > budget
    np.testing.assert_allclose(ens.q[:, -1, 0], np.cos(STEPS * 0.01 / np.sqrt([0.5, 1.0, 2.0])),
                               atol=1e-7)


def test_small_ensembles_save_every_step_and_an_explicit_save_every_is_kept(monkeypatch, recwarn):
    assert len(_ensemble().t) == STEPS + 1
    monkeypatch.setattr(ensemble_module, "OUTPUT_BUDGET_BYTES", 20_000)
    assert len(_ensemble(save_every=1).t) == STEPS + 1
    assert not [w for w in recwarn if "save_every" in str(w.message)]


def test_the_warm_up_of_the_ensemble_glue_prints_the_compile_notice(monkeypatch, capsys,
                                                                   tmp_path):
    """A module generated just now (nothing of it in numba's cache): its first specialized
    ensemble compiles its own glue and says so; the second call compiles nothing and says
    nothing. (The portable ensemble glue, compiled once for every model, reaches a new model's
    native kernels without compiling: jit/native.py.)"""
    from lagrange_gen.codegen.generated_files import generate_model
    fresh = generate_model(ROOT / "models" / "damped_oscillator.py", tmp_path,
                           methods=["rk4"]).path
    monkeypatch.setattr(compile_notice, "NOTICE_AFTER_S", 0.0)
    run = dict(q0=[1.0], t_end=0.05, h=0.01, save_every=1, jit="specialized")
    lg.ensemble(fresh, "rk4", **run)
    err = capsys.readouterr().err
    assert "lagrange-gen: compiling ensemble_rk4 for damped_oscillator (first use) ..." in err
    lg.ensemble(fresh, "rk4", **run)
    assert "compiling" not in capsys.readouterr().err


def test_sweep_reports_compile_time_apart_from_stepping(tmp_path, capsys):
    args = ["sweep", str(DAMPED), "--method", "rk4", "--grid", "c=0.5:2:4", "--q0", "1",
            "--t-end", "1", "--h", "0.01"]
    assert main(args) == 0
    line = capsys.readouterr().out.splitlines()[0]
    assert "s stepping" in line and "compiling/loading the loop" in line and "in all" in line


def test_to_dataframe_is_one_row_per_member_and_saved_state():
    ens = _ensemble(save_every=100)
    frame = ens.to_dataframe()
    M, S = ens.q.shape[:2]
    assert list(frame.columns) == ["member", "m", "c", "b", "t", "x", "x_dot", "energy"]
    assert len(frame) == M * S
    np.testing.assert_array_equal(frame["member"], np.repeat(np.arange(M), S))
    np.testing.assert_array_equal(frame["t"], np.tile(ens.t, M))
    np.testing.assert_array_equal(frame["c"], np.repeat([0.5, 1.0, 2.0], S))
    np.testing.assert_array_equal(frame["x"], ens.q[:, :, 0].ravel())
    np.testing.assert_array_equal(frame["x_dot"], ens.v[:, :, 0].ravel())
    # the closed form through the frame: x = cos(t / sqrt(m c))
    np.testing.assert_allclose(frame["x"], np.cos(frame["t"] / np.sqrt(frame["m"] * frame["c"])),
                               atol=1e-7)


def test_to_dataframe_without_pandas_says_how_to_get_it(monkeypatch):
    import builtins
    real_import = builtins.__import__

    def no_pandas(name, *args, **kwargs):
        if name == "pandas" or name.startswith("pandas."):
            raise ImportError("No module named 'pandas'")
        return real_import(name, *args, **kwargs)
    ens = _ensemble(save_every=100)
    monkeypatch.setattr(builtins, "__import__", no_pandas)
    with pytest.raises(lg.LagrangeGenError, match=r"to_dataframe needs pandas: pip install "
                                                  r"'lagrange-gen\[dataframe\]'"):
        ens.to_dataframe()
