"""Trajectory.save/load round-trip every field; to_dataframe; older npz files; bad files."""

import dataclasses
import sys

import numpy as np
import pytest

from lagrange_gen import LagrangeGenError, Trajectory

KINDS = ("pendulum", "constrained", "nonsmooth", "events")


def assert_same_field(name, a, b):
    if isinstance(a, np.ndarray):
        assert isinstance(b, np.ndarray), name
        assert a.dtype == b.dtype and a.shape == b.shape, name
        assert a.tobytes() == b.tobytes(), name        # bitwise, also structured (events)
    elif isinstance(a, dict) and a and isinstance(next(iter(a.values())), np.ndarray):
        assert list(a) == list(b), name
        for key in a:
            assert_same_field(f"{name}.{key}", a[key], b[key])
    else:
        a = a.item() if isinstance(a, np.generic) else a     # an adaptive run's h is np.float64
        assert a == b and type(a) is type(b), (name, a, b)


@pytest.mark.parametrize("kind", KINDS)
def test_save_load_round_trips_every_field(run, kind, tmp_path):
    traj = run(kind)
    traj = Trajectory(**{**traj.__dict__, "warnings": [f"a warning line of the {kind} run"]})
    traj.save(tmp_path / "sub" / "traj.npz")
    back = Trajectory.load(tmp_path / "sub" / "traj.npz")
    for f in dataclasses.fields(Trajectory):
        assert_same_field(f.name, getattr(traj, f.name), getattr(back, f.name))


def test_the_runs_have_what_the_round_trip_must_carry(run):
    """The round trip above is only worth something if the runs fill the fields."""
    assert run("constrained").saved["multipliers"].shape[1] == 1
    assert run("nonsmooth").element_names == ("slider",)
    events = run("events")
    assert len(events.events) >= 2 and events.step_counts["accepted"] > 0
    assert events.source["model_file"].endswith("cart_pendulum_events.py")
    assert run("pendulum").params["l2"] == 1.0 and run("pendulum").method == "rk4"


def test_a_file_of_the_older_writer_loads(run, tmp_path):
    traj = run("constrained")
    np.savez(tmp_path / "old.npz", t=traj.t, q=traj.q, v=traj.v, energy=traj.energy,
             newton_iters=traj.newton_iters, newton_residual=traj.newton_residual,
             method=traj.method, h=traj.h, model=traj.model, coords=np.array(traj.coords),
             param_names=np.array(list(traj.params)),
             param_values=np.array(list(traj.params.values())), n_steps=traj.n_steps,
             element_names=np.array((), dtype=str),
             constraint_names=np.array(traj.constraint_names, dtype=str),
             multipliers=traj.multipliers, constraint_error=traj.constraint_error,
             velocity_constraint_error=traj.velocity_constraint_error,
             element_state=np.zeros((len(traj.t), 0)))
    back = Trajectory.load(tmp_path / "old.npz")
    np.testing.assert_array_equal(back.q, traj.q)
    np.testing.assert_array_equal(back.multipliers, traj.multipliers)
    np.testing.assert_array_equal(back.constraint_error, traj.constraint_error)
    assert back.params == traj.params and back.constraint_names == traj.constraint_names
    assert "element_state" not in back.saved and back.method == "rattle"


def test_not_a_trajectory_is_one_line(tmp_path):
    np.savez(tmp_path / "other.npz", x=np.zeros(3))
    with pytest.raises(LagrangeGenError, match=r"other.npz: not a lagrange-gen trajectory \(no t,"):
        Trajectory.load(tmp_path / "other.npz")
    (tmp_path / "text.npz").write_text("hello")
    with pytest.raises(LagrangeGenError, match="text.npz: cannot read as a trajectory"):
        Trajectory.load(tmp_path / "text.npz")


def test_to_dataframe_columns_and_values(run):
    pd = pytest.importorskip("pandas")
    traj = run("constrained")
    df = traj.to_dataframe()
    assert isinstance(df, pd.DataFrame) and df.index.name == "t"
    assert list(df.columns) == ["x", "y", "x_dot", "y_dot", "energy", "newton_iters", "lam_0",
                                "constraint_error", "velocity_constraint_error"]
    np.testing.assert_array_equal(df.index.to_numpy(), traj.t)
    np.testing.assert_array_equal(df[["x", "y"]].to_numpy(), traj.q)
    np.testing.assert_array_equal(df["y_dot"].to_numpy(), traj.v[:, 1])
    np.testing.assert_array_equal(df["energy"].to_numpy(), traj.energy)
    np.testing.assert_array_equal(df["lam_0"].to_numpy(), traj.multipliers[:, 0])
    np.testing.assert_array_equal(df["velocity_constraint_error"].to_numpy(),
                                  traj.velocity_constraint_error)


def test_to_dataframe_without_pandas_names_the_extra(run, monkeypatch):
    monkeypatch.setitem(sys.modules, "pandas", None)      # import pandas raises ImportError
    with pytest.raises(LagrangeGenError, match=r"pip install 'lagrange-gen\[dataframe\]'"):
        run("pendulum").to_dataframe()
