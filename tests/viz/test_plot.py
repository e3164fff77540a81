"""The trajectory figure, inspected: which axes, their labels, and that each line's data is the
trajectory's own array (no pixels compared)."""

import numpy as np
import pytest

from lagrange_gen import Trajectory
from lagrange_gen.viz.plot import MAX_ROWS


def by_label(fig):
    """{y label: axes}; labels are unique in these figures."""
    axes = {ax.get_ylabel(): ax for ax in fig.axes}
    assert len(axes) == len(fig.axes)
    return axes


def line(ax, label=None):
    lines = ax.get_lines() if label is None else [l for l in ax.get_lines() if l.get_label() == label]
    assert len(lines) == 1
    return lines[0].get_xdata(), lines[0].get_ydata()


def test_one_axis_per_coordinate_and_velocity_and_the_energy(run):
    traj = run("pendulum")
    fig = traj.plot()
    axes = by_label(fig)
    assert list(axes) == ["th1", "th1_dot", "th2", "th2_dot", "E - E0"]
    for i, name in enumerate(traj.coords):
        t, y = line(axes[name])
        np.testing.assert_array_equal(t, traj.t)
        np.testing.assert_array_equal(y, traj.q[:, i])
        np.testing.assert_array_equal(line(axes[f"{name}_dot"])[1], traj.v[:, i])
    np.testing.assert_array_equal(line(axes["E - E0"])[1], traj.energy - traj.energy[0])
    assert axes["E - E0"].get_xlabel() == "t" and "rk4" in fig.get_suptitle()


def test_constrained_run_shows_errors_and_multipliers(run):
    traj = run("constrained")
    axes = by_label(traj.plot())
    assert set(axes) == {"x", "x_dot", "y", "y_dot", "E - E0", "|Phi|, |J v|", "multipliers"}
    errors = axes["|Phi|, |J v|"]
    assert errors.get_yscale() == "log"
    for label, values in (("|Phi|", traj.constraint_error),
                          ("|J v|", traj.velocity_constraint_error)):
        y = line(errors, label)[1]
        nonzero = values > 0              # exact zeros are drawn on a floor below the others
        assert nonzero.any() and not nonzero.all()
        np.testing.assert_array_equal(y[nonzero], values[nonzero])
        floor = y[~nonzero]
        assert np.all(floor == floor[0]) and 0 < floor[0] < values[nonzero].min()
    np.testing.assert_array_equal(line(axes["multipliers"], "lam_0")[1], traj.multipliers[:, 0])


def test_nonsmooth_run_shows_element_states(run):
    traj = run("nonsmooth")
    axes = by_label(traj.plot())
    assert set(axes) == {"x", "x_dot", "E - E0 - W", "element state"}   # F(t) does work
    y = line(axes["element state"], "slider")[1]
    np.testing.assert_array_equal(y, traj.element_state[:, 0])
    assert np.ptp(y) > 0.5                # the element yielded: the panel shows something


def test_energy_balance_when_the_trajectory_has_work(run):
    traj = run("pendulum")
    work = np.linspace(0.0, 2.0, len(traj.t)) + 5.0
    traj_with_work = Trajectory(**{**traj.__dict__})
    traj_with_work.work = work
    axes = by_label(traj_with_work.plot())
    assert "E - E0 - W" in axes and "E - E0" not in axes
    np.testing.assert_allclose(line(axes["E - E0 - W"])[1],
                               traj.energy - traj.energy[0] - (work - 5.0), rtol=0, atol=1e-15)


def test_many_coordinates_share_one_axis_per_kind():
    n, S = MAX_ROWS + 2, 5
    q = np.arange(S * n, dtype=float).reshape(S, n)
    traj = Trajectory(t=np.arange(S, dtype=float), q=q, v=-q, energy=np.ones(S),
                      newton_iters=np.zeros(S), newton_residual=np.zeros(S), method="rk4", h=1.0,
                      model="chain", params={}, coords=tuple(f"c{i}" for i in range(n)), n_steps=4)
    axes = by_label(traj.plot())
    assert list(axes) == ["q", "v", "E - E0"]
    np.testing.assert_array_equal(line(axes["q"], "c7")[1], q[:, 7])
    np.testing.assert_array_equal(line(axes["v"], "c9_dot")[1], -q[:, 9])


@pytest.mark.parametrize("suffix", [".png", ".svg"])
def test_plot_writes_the_file(run, tmp_path, suffix):
    path = tmp_path / "deep" / f"traj{suffix}"
    assert run("constrained").plot(path) is None
    head = path.read_bytes()[:8]
    assert head == b"\x89PNG\r\n\x1a\n" if suffix == ".png" else b"<?xml" in head
