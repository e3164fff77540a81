"""`lagrange-gen animate`: a saved trajectory (.npz of simulate --out) as a GIF or MP4.

    lagrange-gen simulate models/double_pendulum.py --method rk4 --h 1e-3 --t-end 5 \\
        --q0 2 2.5 --out dp.npz
    lagrange-gen animate dp.npz --out dp.gif --fps 20

The npz records the model file it came from (and its build options, frozen parameters); --model
gives another one (a moved file, or a copy with a different drawing). cli/main.py wires ``add_parser``
and ``run`` in; errors are LagrangeGenError (one line, no traceback).
"""

from __future__ import annotations

from pathlib import Path

from .simulate import check_output_path
from ..viz.animate import SUFFIXES, check_positive


def add_parser(subparsers):
    """Add the ``animate`` subcommand to an argparse subparsers object."""
    p = subparsers.add_parser(
        "animate", help="animate a saved trajectory with its model's drawing",
        description="Write a GIF (or an MP4 when ffmpeg is installed) of the points and segments "
                    "the model declares with Model(..., draw=Drawing(...)), moved along a "
                    "trajectory saved by `lagrange-gen simulate --out FILE.npz`.")
    p.add_argument("trajectory", metavar="TRAJ.npz", help="trajectory written by simulate --out")
    p.add_argument("--out", metavar="FILE", help="animation file, .gif or .mp4 "
                                                  "(default: TRAJ.gif next to the trajectory)")
    p.add_argument("--model", metavar="MODEL.py",
                   help="model file whose drawing is used (default: the one the run recorded)")
    p.add_argument("--frames", type=int, metavar="N",
                   help="number of frames, evenly spaced in time (default: real time at --fps, "
                        "at most 300)")
    p.add_argument("--fps", type=float, default=25.0, help="frames per second (default 25)")
    p.add_argument("--dpi", type=int, default=80, help="resolution (default 80: 400x400 pixels)")
    return p


def run(args) -> int:
    """Run the subcommand; returns the exit status."""
    from ..errors import LagrangeGenError
    from ..run.trajectory import Trajectory
    source = Path(args.trajectory)
    if not source.is_file():
        raise LagrangeGenError(f"{source}: no such trajectory file")
    out = args.out or str(source.with_suffix(".gif"))
    check_output_path("--out", out, SUFFIXES)
    check_positive("--fps", args.fps)
    check_positive("--dpi", args.dpi, integer=True)
    traj = Trajectory.load(source)
    frames = traj.animate(out, model=args.model, frames=args.frames, fps=args.fps, dpi=args.dpi)
    print(f"wrote {out} ({frames} frames at {args.fps:g} fps)")
    return 0
