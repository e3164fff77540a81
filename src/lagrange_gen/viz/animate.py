"""Animations: the model's Drawing (Model(draw=...)) moved along a Trajectory, written as a GIF
(Pillow, through matplotlib's writers) or an MP4 (ffmpeg, when installed).

    traj.animate("pendulum.gif")                     # the model file recorded in traj.source
    lagrange-gen animate traj.npz --out pendulum.gif

Frames are evenly spaced in time, the state at each frame linearly interpolated between saved
rows (default: real time at ``fps``, at most MAX_FRAMES frames). The axes are fixed for the
whole animation and contain every drawn point of every frame, with equal aspect, so the motion
is seen undistorted and the picture never jumps.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import LagrangeGenError

MAX_FRAMES = 300
SUFFIXES = (".gif", ".mp4")


def frame_states(traj, frames):
    """(times (F,), q (F, n)): ``frames`` times evenly spaced over the run, q interpolated."""
    times = np.linspace(traj.t[0], traj.t[-1], frames)
    q = np.column_stack([np.interp(times, traj.t, traj.q[:, i]) for i in range(traj.q.shape[1])])
    return times, q.reshape(frames, traj.q.shape[1])


def default_frames(traj, fps):
    """Real time at ``fps`` (at least 2 frames, at most MAX_FRAMES)."""
    return int(min(MAX_FRAMES, max(2, round((traj.t[-1] - traj.t[0]) * fps) + 1)))


def drawing_model(traj, model=None):
    """The Model whose Drawing is animated: ``model`` (a Model or a model file), else the model
    file recorded in traj.source, built with its build options."""
    from ..model.model import Model
    from ..model.model_file import load_model
    if isinstance(model, Model):
        return model
    if model is not None:
        return load_model(model, **traj.source.get("build", {}))
    path = traj.source.get("model_file")
    if not path:
        raise LagrangeGenError(f"trajectory of {traj.model} does not record its model file: pass "
                               "the model (model= or --model MODEL.py)")
    if not Path(path).is_file():
        raise LagrangeGenError(f"{path}: the model file of this trajectory is gone: pass the "
                               "model (model= or --model MODEL.py)")
    return load_model(path, **traj.source.get("build", {}))


def point_positions(traj, model, frames):
    """(times (F,), positions (F, P, dim)) of the Drawing's points at ``frames`` frame times,
    with the trajectory's parameters (frozen ones from traj.source)."""
    from ..model.drawing import positions_function
    if [c.name for c in model.coords] != list(traj.coords):
        raise LagrangeGenError(f"model {model.name} has coordinates "
                               f"{', '.join(c.name for c in model.coords)}, the trajectory "
                               f"{', '.join(traj.coords)}: not the model of this run")
    values = {**model.param_defaults, **traj.source.get("frozen", {}), **traj.params}
    missing = [p.name for p in model.params if values.get(p.name) is None]
    if missing:
        raise LagrangeGenError(f"model {model.name}: no value for parameter(s) {', '.join(missing)}")
    times, q = frame_states(traj, frames)
    return times, positions_function(model)(q, [values[p.name] for p in model.params], times)


def check_positive(name, value, integer=False):
    """LagrangeGenError (one line naming ``name``) unless ``value`` is a finite number > 0 (an
    integer >= 1 when ``integer``): a frame rate of nan, inf or 0 has no frame spacing."""
    import math
    import numbers
    if integer:
        ok = isinstance(value, numbers.Integral) and not isinstance(value, bool) and value >= 1
        if not ok:
            raise LagrangeGenError(f"{name} must be an integer >= 1, got {value!r}")
        return
    ok = (isinstance(value, numbers.Real) and not isinstance(value, bool)
          and math.isfinite(value) and value > 0)
    if not ok:
        raise LagrangeGenError(f"{name} must be a finite number > 0, got {value!r}")


def animate(traj, path, model=None, frames=None, fps=25, dpi=80):
    """Write the animation of ``traj`` to ``path`` (.gif or .mp4); returns the frame count.
    fps: frames per second, a finite number > 0; dpi: an integer >= 1."""
    check_positive("fps", fps)
    check_positive("dpi", dpi, integer=True)
    path = Path(path)
    writer = _writer(path, fps)
    frames = default_frames(traj, fps) if frames is None else int(frames)
    if frames < 1:
        raise LagrangeGenError(f"animate: frames must be >= 1, got {frames}")
    model = drawing_model(traj, model)
    times, xyz = point_positions(traj, model, frames)
    fig, update = _scene(model, xyz, f"{traj.model} ({traj.method})")
    path.parent.mkdir(parents=True, exist_ok=True)
    with writer.saving(fig, str(path), dpi):
        for k in range(frames):
            update(k, times[k])
            writer.grab_frame()
    return frames


def _writer(path, fps):
    from matplotlib import animation
    if path.suffix not in SUFFIXES:
        raise LagrangeGenError(f"{path}: use a .gif or .mp4 file name")
    if path.suffix == ".mp4":
        if not animation.writers.is_available("ffmpeg"):
            raise LagrangeGenError(f"{path}: writing .mp4 needs ffmpeg on PATH; write a .gif instead")
        return animation.FFMpegWriter(fps=fps)
    return animation.PillowWriter(fps=fps)


def _scene(model, xyz, title):
    """(Figure, update(frame, time)): fixed limits over all frames, equal aspect; segments as
    lines, points as markers, the time as text."""
    from matplotlib.figure import Figure
    draw, dim = model.draw, xyz.shape[2]
    index = {name: i for i, name in enumerate(draw.names)}
    pairs = [(index[a], index[b]) for a, b in draw.segments]
    lo, hi = xyz.min(axis=(0, 1)), xyz.max(axis=(0, 1))
    centre, half = (lo + hi) / 2, max(float((hi - lo).max()) / 2, 1e-9) * 1.1
    fig = Figure(figsize=(5, 5))
    ax = fig.add_subplot(projection="3d" if dim == 3 else None)
    for axis, c in zip("xyz", centre):
        getattr(ax, f"set_{axis}lim")(c - half, c + half)
        getattr(ax, f"set_{axis}label")(axis)
    if dim == 3:
        ax.set_box_aspect((1, 1, 1))
    else:
        ax.set_aspect("equal")
    ax.set_title(title)
    lines = [ax.plot(*([0, 0],) * dim, "-", lw=2, color="0.3")[0] for _ in pairs]
    marks = ax.plot(*([0] * len(index),) * dim, "o", ms=7, color="tab:red")[0]
    label = ax.text2D(0.02, 0.95, "", transform=ax.transAxes) if dim == 3 else \
        ax.text(0.02, 0.95, "", transform=ax.transAxes)

    def update(k, time):
        p = xyz[k]
        for line, (a, b) in zip(lines, pairs):
            line.set_data(p[[a, b], 0], p[[a, b], 1])
            if dim == 3:
                line.set_3d_properties(p[[a, b], 2])
        marks.set_data(p[:, 0], p[:, 1])
        if dim == 3:
            marks.set_3d_properties(p[:, 2])
        label.set_text(f"t = {time:.2f}")
    return fig, update
