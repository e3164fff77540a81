"""EnsembleResult: parameters by name, a file that loads back field for field (failed members'
messages included), and a plot whose lines are the members' own arrays."""

from pathlib import Path

import numpy as np
import pytest

import lagrange_gen as lg
from lagrange_gen.codegen import generate_model
from lagrange_gen.errors import LagrangeGenError
from lagrange_gen.run.ensemble import EnsembleResult
from lagrange_gen.run.loader import import_generated
from lagrange_gen.steppers.core import status

MODELS = Path(__file__).resolve().parents[2] / "models"


@pytest.fixture(scope="module")
def ens(tmp_path_factory):
    out = tmp_path_factory.mktemp("ensemble_files_gen")
    cart = import_generated(generate_model(MODELS / "cart_pendulum.py", out,
                                           methods=["explicit_euler"]).path)
    q0 = np.array([[0.1, 0.5], [0.2, 0.4], [0.0, 0.3], [0.3, 0.1]])
    v0 = np.zeros((4, 2))
    v0[2] = [0.0, 40.0]                  # explicit Euler spins this one past the bound
    return lg.ensemble(cart, "explicit_euler", q0=q0, v0=v0,
                       params={"k": [5.0, 10.0, 15.0, 20.0]}, t_end=2.0, h=0.01,
                       save_every=10, blowup_bound=60.0)


def test_params_by_name(ens):
    by_name = ens.params_by_name
    assert list(by_name) == list(ens.param_names)
    np.testing.assert_array_equal(by_name["k"], [5.0, 10.0, 15.0, 20.0])
    for j, name in enumerate(ens.param_names):
        np.testing.assert_array_equal(by_name[name], ens.params[:, j])


def test_save_load_round_trip(ens, tmp_path):
    assert ens.status[2] == status.UNSTABLE and ens.messages
    path = tmp_path / "sub" / "ens.npz"
    ens.save(path)
    back = EnsembleResult.load(path)
    for name, value in vars(ens).items():
        other = getattr(back, name)
        if isinstance(value, np.ndarray):
            np.testing.assert_array_equal(other, value)
            assert other.dtype == value.dtype, name
        elif name == "saved":
            assert list(other) == list(value)
            for key in value:
                np.testing.assert_array_equal(other[key], value[key])
        else:
            assert other == value and type(other) is type(value), name
    assert back.failures() == ens.failures()


def test_files_are_not_mixed_up(ens, tmp_path, generated):
    ens.save(tmp_path / "ens.npz")
    with pytest.raises(LagrangeGenError, match=r"ens\.npz: .*ensemble.*EnsembleResult\.load"):
        lg.Trajectory.load(tmp_path / "ens.npz")
    traj = lg.simulate(generated("bouncing_ball"), "dop853_impacts", [1.0], t_end=0.1)
    traj.save(tmp_path / "traj.npz")
    with pytest.raises(LagrangeGenError, match=r"traj\.npz: .*Trajectory\.load"):
        EnsembleResult.load(tmp_path / "traj.npz")
    (tmp_path / "junk.npz").write_text("junk")
    with pytest.raises(LagrangeGenError, match=r"junk\.npz: cannot read"):
        EnsembleResult.load(tmp_path / "junk.npz")


def test_plot_draws_every_member(ens, tmp_path):
    fig = ens.plot()
    axes = {ax.get_ylabel(): ax for ax in fig.axes}
    assert list(axes) == ["x", "x_dot", "theta", "theta_dot", "E - E0"]
    for i, name in enumerate(ens.coords):
        lines = axes[name].get_lines()
        assert len(lines) == len(ens.q)
        for member, line in enumerate(lines):
            np.testing.assert_array_equal(line.get_xdata(), ens.t)
            np.testing.assert_array_equal(line.get_ydata(), ens.q[member, :, i])
        assert [line.get_label() for line in lines][:2] == ["k=5", "k=10"]
    energy = axes["E - E0"].get_lines()
    np.testing.assert_array_equal(energy[1].get_ydata(), ens.energy[1] - ens.energy[1, 0])
    path = tmp_path / "ens.png"
    assert ens.plot(path) is None and path.stat().st_size > 0
