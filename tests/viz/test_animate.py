"""Animations as a user makes them: traj.animate and `lagrange-gen animate traj.npz`; GIFs read
back with PIL; the drawn positions against closed forms; fixed axes that hold the whole motion."""

import shutil

import numpy as np
import pytest
from PIL import Image, ImageChops

from lagrange_gen import LagrangeGenError, ModelError, Trajectory
from lagrange_gen.cli.main import main
from lagrange_gen.model.model_file import load_model
from lagrange_gen.viz.animate import _scene, default_frames, frame_states, point_positions
from tests.conftest import MODELS_DIR


def gif_frames(path):
    with Image.open(path) as im:
        assert im.format == "GIF"
        frames = []
        for k in range(im.n_frames):
            im.seek(k)
            frames.append(im.convert("RGB"))
        return frames


def test_traj_animate_writes_a_gif_with_the_frames_asked(run, tmp_path):
    traj = run("pendulum")
    path = tmp_path / "out" / "pendulum.gif"
    assert traj.animate(path, frames=12, fps=10, dpi=40) == 12
    frames = gif_frames(path)
    assert len(frames) == 12 and frames[0].size == (200, 200)
    # every frame differs from the one before (the pendulum moves, the clock runs)
    assert all(ImageChops.difference(a, b).getbbox() for a, b in zip(frames, frames[1:]))


def test_frames_are_evenly_spaced_in_time_and_interpolated(run):
    traj = run("pendulum")                      # saved every 0.02 s to t = 2
    times, q = frame_states(traj, 11)
    np.testing.assert_allclose(times, np.linspace(0, 2, 11), atol=1e-15)
    np.testing.assert_allclose(q, traj.q[::10], rtol=1e-12)   # frame times on saved rows
    _, q_mid = frame_states(traj, 201)
    np.testing.assert_allclose(q_mid[1], (traj.q[0] + traj.q[1]) / 2, rtol=1e-12)
    assert default_frames(traj, fps=25) == 51 and default_frames(traj, fps=1000) == 300


def test_positions_at_a_frame_are_the_closed_form(run):
    """The points animate draws at frame k: the bobs at the interpolated q, with the run's
    parameters (not the defaults)."""
    traj = run("pendulum")
    traj = Trajectory(**{**traj.__dict__, "params": {**traj.params, "l2": 0.5}})
    model = load_model(MODELS_DIR / "double_pendulum.py")
    times, xyz = point_positions(traj, model, 11)
    q = traj.q[::10]
    m1 = np.column_stack([np.sin(q[:, 0]), -np.cos(q[:, 0])])
    m2 = m1 + 0.5 * np.column_stack([np.sin(q[:, 1]), -np.cos(q[:, 1])])
    np.testing.assert_allclose(xyz[:, 1], m1, atol=1e-15)
    np.testing.assert_allclose(xyz[:, 2], m2, atol=1e-15)


@pytest.mark.parametrize("stem, dim", [("double_pendulum", 2), ("spherical_pendulum", 3)])
def test_axes_are_fixed_equal_and_hold_every_point(stem, dim):
    model = load_model(MODELS_DIR / f"{stem}.py")
    rng = np.random.default_rng(3)
    xyz = rng.normal(size=(20, len(model.draw.names), dim)) * [1.0, 3.0, 0.5][:dim]
    fig, update = _scene(model, xyz, "title")
    ax = fig.axes[0]
    limits = [getattr(ax, f"get_{a}lim")() for a in "xyz"[:dim]]
    spans = [hi - lo for lo, hi in limits]
    np.testing.assert_allclose(spans, spans[0])            # one scale on every axis
    for (lo, hi), k in zip(limits, range(dim)):
        assert lo < xyz[..., k].min() and xyz[..., k].max() < hi
    update(4, 0.5)
    marks = ax.get_lines()[-1]
    data = marks.get_data_3d() if dim == 3 else marks.get_data()
    np.testing.assert_array_equal(np.column_stack(data), xyz[4])
    assert [getattr(ax, f"get_{a}lim")() for a in "xyz"[:dim]] == limits   # unchanged by update
    if dim == 2:
        assert ax.get_aspect() == 1.0


def test_cli_animate_a_saved_run(run, tmp_path, capsys):
    traj = run("pendulum")
    traj.save(tmp_path / "dp.npz")
    assert main(["animate", str(tmp_path / "dp.npz"), "--frames", "5", "--dpi", "30"]) == 0
    assert "wrote" in capsys.readouterr().out
    assert len(gif_frames(tmp_path / "dp.gif")) == 5


def test_cli_animate_with_another_model_file(run, tmp_path, capsys):
    """The recorded model file is gone: --model names one."""
    traj = run("pendulum")
    traj = Trajectory(**{**traj.__dict__, "source": {**traj.source,
                                                     "model_file": str(tmp_path / "moved.py")}})
    traj.save(tmp_path / "dp.npz")
    assert main(["animate", str(tmp_path / "dp.npz"), "--out", str(tmp_path / "a.gif")]) == 2
    assert "moved.py: the model file of this trajectory is gone: pass the model" in capsys.readouterr().err
    shutil.copy(MODELS_DIR / "double_pendulum.py", tmp_path / "copy.py")
    assert main(["animate", str(tmp_path / "dp.npz"), "--model", str(tmp_path / "copy.py"),
                 "--out", str(tmp_path / "a.gif"), "--frames", "3", "--dpi", "30"]) == 0
    assert len(gif_frames(tmp_path / "a.gif")) == 3


@pytest.mark.parametrize("args, message", [
    (["--out", "x.avi"], "x.avi: use a .gif or .mp4 file name"),
    (["--model", "MODELS/kepler.py"], "model kepler has coordinates r, phi, the trajectory th1, th2"),
    (["--frames", "0"], "animate: frames must be >= 1, got 0"),
    (["--fps", "0"], "--fps must be a finite number > 0, got 0.0"),
])
def test_cli_animate_errors_are_one_line(run, tmp_path, capsys, args, message):
    run("pendulum").save(tmp_path / "dp.npz")
    args = [a.replace("MODELS", str(MODELS_DIR)) for a in args]
    assert main(["animate", str(tmp_path / "dp.npz"), *args]) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1


def test_a_model_without_a_drawing_is_refused(run, tmp_path):
    with pytest.raises(ModelError, match="model cart_pendulum_events declares nothing to draw"):
        run("events").animate(tmp_path / "x.gif")


def test_mp4_needs_ffmpeg(run, tmp_path):
    from matplotlib import animation
    if animation.writers.is_available("ffmpeg"):
        run("pendulum").animate(tmp_path / "x.mp4", frames=3, dpi=30)
        assert (tmp_path / "x.mp4").stat().st_size > 0
    else:
        with pytest.raises(LagrangeGenError, match="writing .mp4 needs ffmpeg on PATH"):
            run("pendulum").animate(tmp_path / "x.mp4")


def test_cli_simulate_out_then_animate(tmp_path, capsys):
    """The whole user path: simulate --out --plot, then animate the npz."""
    npz, png = tmp_path / "c.npz", tmp_path / "c.png"
    assert main(["simulate", str(MODELS_DIR / "cart_pendulum.py"), "--method", "rk4", "--h",
                 "0.01", "--t-end", "0.5", "--q0", "0.1", "0.5", "--out", str(npz), "--plot",
                 str(png), "--gen-dir", str(tmp_path / "gen")]) == 0
    assert Trajectory.load(npz).source["model_file"] == str(MODELS_DIR / "cart_pendulum.py")
    assert png.read_bytes()[:4] == b"\x89PNG"
    assert main(["animate", str(npz), "--fps", "10", "--dpi", "30"]) == 0
    assert len(gif_frames(tmp_path / "c.gif")) == 6          # real time: 0.5 s at 10 fps, +1


def test_frozen_parameters_and_build_options_come_from_the_source(run):
    """A module generated with --freeze l2=0.5 has no l2 in traj.params: the drawing takes it
    from traj.source; a family's build options rebuild the same member (n = 2 links)."""
    traj = run("pendulum")
    params = {k: v for k, v in traj.params.items() if k != "l2"}
    source = {"model_file": str(MODELS_DIR / "n_link_pendulum.py"), "build": {"n": 2}}
    chain = Trajectory(**{**traj.__dict__, "coords": ("th1", "th2"), "params": params,
                          "source": {**source, "frozen": {}}})
    _, xyz = point_positions(chain, load_model(MODELS_DIR / "n_link_pendulum.py", n=2), 3)
    assert xyz.shape == (3, 3, 2)
    from lagrange_gen.viz.animate import drawing_model
    assert drawing_model(chain).name == "n_link_pendulum_2"
    frozen = Trajectory(**{**traj.__dict__, "params": params,
                           "source": {**traj.source, "frozen": {"l2": 0.5}}})
    _, xyz = point_positions(frozen, load_model(MODELS_DIR / "double_pendulum.py"), 2)
    q = frozen.q[-1]
    np.testing.assert_allclose(xyz[-1, 2] - xyz[-1, 1], [0.5 * np.sin(q[1]), -0.5 * np.cos(q[1])],
                               atol=1e-15)


def test_simulate_records_where_the_module_came_from(tmp_path):
    from types import SimpleNamespace
    from lagrange_gen.run.run_result import _source
    module = SimpleNamespace(__file__=str(tmp_path / "gen" / "m.py"), MODEL_PATH="../models/m.py",
                             OPTIONS={"build": {"n": 4}, "methods": ["rk4"]}, FROZEN={"g": 9.81})
    assert _source(module) == {"model_file": str(tmp_path / "models" / "m.py"),
                               "build": {"n": 4}, "frozen": {"g": 9.81}}
    assert _source(SimpleNamespace(__file__="x.py")) == {}


def test_a_3d_drawing_animates(tmp_path):
    """The spherical pendulum's drawing is 3D: the GIF is written from a hand-made conical
    motion (q1 fixed, q2 = t), the bob on its circle at every frame."""
    t = np.linspace(0.0, 3.0, 31)
    q = np.column_stack([np.full_like(t, 2.5), t])
    traj = Trajectory(t=t, q=q, v=np.zeros_like(q), energy=np.zeros_like(t),
                      newton_iters=np.zeros_like(t), newton_residual=np.zeros_like(t),
                      method="rk4", h=0.1, model="spherical_pendulum",
                      params={"m": 1.0, "l": 2.0, "g": 9.81}, coords=("q1", "q2"), n_steps=30,
                      source={"model_file": str(MODELS_DIR / "spherical_pendulum.py")})
    assert traj.animate(tmp_path / "sph.gif", frames=4, dpi=30) == 4
    assert len(gif_frames(tmp_path / "sph.gif")) == 4
    _, xyz = point_positions(traj, load_model(MODELS_DIR / "spherical_pendulum.py"), 4)
    np.testing.assert_allclose(xyz[:, 1, 2], 2.0 * np.cos(2.5), atol=1e-15)
    np.testing.assert_allclose(np.arctan2(xyz[:, 1, 1], xyz[:, 1, 0]), [0.0, 1.0, 2.0, 3.0],
                               atol=1e-12)
