"""`lagrange-gen sweep`: an ensemble over a grid of parameters from the command line.

    lagrange-gen sweep models/cart_pendulum.py --method rk4 --grid k=1:100:50 --grid m=0.1:1:20 \\
        --q0 0.1 0.5 --t-end 10 --h 1e-3 --save-every 100 --out sweep.npz --plot sweep.png \\
        --scalar max_amplitude --coord theta

Runs lagrange_gen.ensemble (on every core; with --device cuda one GPU thread per member) over
the Cartesian product of the --grid axes (START:STOP:COUNT, the ends included, or a comma
list), writes the ensemble (npz: t, q, v, energy, status, steps_done,
params, the grid axes and the scalar) and a picture of one scalar per member over the grid (a
curve for one axis, an image for two). Failed members are listed on stderr, one line each, and
are NaN in the scalar. Options shared with `simulate` (q0, v0, --param, the method settings)
mean the same; cli/main.py wires ``add_parser`` and ``run`` in.
"""

from __future__ import annotations

import sys
import time

import numpy as np

from ..errors import SimulationError
from .options import BUILD, method_name, one_line_warnings, out_dir, parse_assignments
from .simulate import (add_setting_options, given_settings, parse_params,
                           check_output_path)

#: The scalars a sweep can picture: name -> (help, function of (ensemble result, coord index)).
SCALARS = {
    "final_energy": ("E at the last saved state", lambda e, c: e.energy[:, -1]),
    "energy_drift": ("max |E - E0| over the run", lambda e, c: np.nanmax(
        np.abs(e.energy - e.energy[:, :1]), axis=1)),
    "max_amplitude": ("max |q[coord]| over the run", lambda e, c: np.nanmax(
        np.abs(e.q[:, :, c]), axis=1)),
    "final_coord": ("q[coord] at the last saved state", lambda e, c: e.q[:, -1, c]),
}


def add_parser(subparsers):
    p = subparsers.add_parser(
        "sweep", help="an ensemble over a parameter grid: npz and a picture of one scalar",
        description="Run one model over the Cartesian product of parameter axes "
                    "(lagrange_gen.ensemble, all cores) and picture a scalar over the grid.")
    p.add_argument("model", metavar="MODEL.py", help="model file or generated module")
    p.add_argument("--method", default="rk4",
                   help="fixed-step method (default: rk4; lagrange-gen simulate --help lists "
                        "them)")
    p.add_argument("--grid", action="append", required=True, metavar="NAME=START:STOP:COUNT",
                   help="a parameter axis (COUNT values from START to STOP), or NAME=A,B,C; "
                        "repeat for more axes")
    p.add_argument("--h", type=float, required=True, help="step size")
    p.add_argument("--t-end", type=float, required=True, help="final time")
    p.add_argument("--q0", type=float, nargs="+", metavar="Q", help="initial coordinates")
    p.add_argument("--v0", type=float, nargs="+", metavar="V", help="initial velocities")
    p.add_argument("--param", action="append", default=[], metavar="NAME=VALUE,...",
                   help="parameters shared by every member, e.g. k=20,m=0.5; repeatable")
    p.add_argument("--set", action="append", metavar="NAME=VALUE,...", dest="options",
                   help="options passed to the model file's build() (e.g. n=8), repeatable")
    p.add_argument("--save-every", type=int, metavar="K",
                   help="keep every K-th state (default: every state unless the ensemble would "
                        "hold more than 256 MB; then the smallest K that fits, said on stderr)")
    p.add_argument("--scalar", default="final_energy", choices=sorted(SCALARS),
                   help="; ".join(f"{k}: {text}" for k, (text, _) in SCALARS.items()))
    p.add_argument("--coord", metavar="NAME", help="coordinate of max_amplitude / final_coord "
                                                   "(default: the first)")
    p.add_argument("--out", metavar="FILE.npz", help="write the ensemble")
    p.add_argument("--plot", metavar="FILE.png", help="picture of the scalar over the grid")
    p.add_argument("--gen-dir", metavar="DIR",
                   help="where model files are generated (default: as lagrange-gen's -o, "
                        "generated/ beside the model file or its models/ folder)")
    p.add_argument("--progress", action="store_true", help="show a progress bar on stderr")
    p.add_argument("--device", default="cpu", choices=("cpu", "cuda"),
                   help="cpu: every core; cuda: one GPU thread per member (needs numba-cuda, "
                        "the gpu extra, and a GPU)")
    p.add_argument("--dtype", default="float64", choices=("float64", "float32"),
                   help="arithmetic of the members on --device cuda (default float64)")
    add_setting_options(p)
    return p


def parse_axis(text):
    """'k=1:100:50' -> ('k', linspace(1, 100, 50)); 'k=1,2,5' -> ('k', [1, 2, 5])."""
    name, sep, spec = text.partition("=")
    name = name.strip()
    try:
        if not sep or not name:
            raise ValueError
        if ":" in spec:
            start, stop, count = spec.split(":")
            if int(count) < 1:
                raise ValueError
            return name, np.linspace(float(start), float(stop), int(count))
        return name, np.array([float(x) for x in spec.split(",")])
    except ValueError:
        raise SimulationError(f"--grid {text}: expected NAME=START:STOP:COUNT (COUNT >= 1) or "
                              f"NAME=A,B,C with numbers") from None


def run(args) -> int:
    """Run the subcommand; returns the exit status (0, also when some members failed)."""
    from ..run.ensemble import ensemble
    from ..run.ensemble_inputs import grid
    method_name(args.method, SimulationError)
    axes = dict(parse_axis(text) for text in args.grid)
    if len(axes) != len(args.grid):
        raise SimulationError("--grid: each parameter may be given once")
    if args.out:
        check_output_path("--out", args.out, (".npz",))
    if args.plot:
        check_output_path("--plot", args.plot, (".png", ".pdf", ".svg"))
        if len(axes) > 2:
            raise SimulationError(f"--plot pictures one or two grid axes; {len(axes)} given "
                                  f"({', '.join(axes)})")
    shared = parse_params(args.param)
    both = sorted(set(shared) & set(axes))
    if both:
        raise SimulationError(f"parameter {both[0]!r} is given both by --grid and --param")
    options = parse_assignments(args.options, "--set", BUILD, SimulationError)
    gen_dir = out_dir(args.model, args.gen_dir)
    start = time.perf_counter()
    with one_line_warnings():
        model = args.model
        if options:
            from ..run.simulate import load_module
            model = load_module(model, gen_dir, args.method, options=options)
        result = ensemble(model, args.method, q0=args.q0, v0=args.v0,
                          params={**shared, **grid(**axes)}, t_end=args.t_end, h=args.h,
                          save_every=args.save_every, progress=args.progress,
                          out_dir=gen_dir, device=args.device, dtype=args.dtype,
                          **given_settings(args))
    elapsed = time.perf_counter() - start
    coord = _coord_index(result, args.coord)
    scalar = SCALARS[args.scalar][1](result, coord)
    scalar = np.where(result.ok, scalar, np.nan)
    for line in result.failures():
        print(f"lagrange-gen: failed: {line}", file=sys.stderr)
    print(f"{result.model}, {result.method}: {len(result.status)} members over "
          f"{' x '.join(f'{k} ({len(v)})' for k, v in axes.items())}, "
          f"{int((~result.ok).sum())} failed; {result.wall_time:.3g} s stepping"
          + (f" on {result.device}" if result.device != "cpu" else "")
          + f", {result.compile_time:.3g} s compiling/loading the loop, {elapsed:.3g} s in all "
            f"(with generating and loading the model)")
    if args.out:
        _write_npz(args.out, result, axes, args.scalar, scalar)
        print(f"wrote {args.out}")
    if args.plot:
        _plot(args.plot, result, axes, args.scalar, scalar, coord)
        print(f"wrote {args.plot}")
    return 0


def _coord_index(result, name):
    if name is None:
        return 0
    if name not in result.coords:
        raise SimulationError(f"--coord {name}: the model's coordinates are "
                              f"{', '.join(result.coords)}")
    return result.coords.index(name)


def _write_npz(path, result, axes, scalar_name, scalar):
    arrays = {f"axis_{name}": values for name, values in axes.items()}
    np.savez_compressed(path, t=result.t, q=result.q, v=result.v, energy=result.energy,
                        status=result.status, steps_done=result.steps_done, params=result.params,
                        param_names=np.array(result.param_names), coords=np.array(result.coords),
                        grid_names=np.array(list(axes)), scalar_name=np.array(scalar_name),
                        scalar=scalar, **arrays)


def _plot(path, result, axes, scalar_name, scalar, coord):
    from ..bench.common import new_figure, save_figure
    names = list(axes)
    label = scalar_name + (f" ({result.coords[coord]})" if "coord" in scalar_name
                           or "amplitude" in scalar_name else "")
    fig, ax = new_figure(figsize=(6, 4.5))
    if len(names) == 1:
        ax.plot(axes[names[0]], scalar, "o-", ms=3)
        ax.set_xlabel(names[0])
        ax.set_ylabel(label)
    else:
        image = scalar.reshape(len(axes[names[0]]), len(axes[names[1]]))
        mesh = ax.pcolormesh(axes[names[1]], axes[names[0]], image, shading="nearest")
        fig.colorbar(mesh, ax=ax, label=label)
        ax.set_xlabel(names[1])
        ax.set_ylabel(names[0])
    ax.set_title(f"{result.model}, {result.method}: {label}")
    save_figure(fig, path)
