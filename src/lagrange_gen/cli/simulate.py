"""`lagrange-gen simulate`: integrate a model from the command line.

    lagrange-gen simulate models/cart_pendulum.py --method midpoint --h 1e-3 --t-end 10 \\
        --q0 0.1 0.5 --v0 0 0 --param k=20 --save-every 10 --out traj.npz --plot traj.png

cli/main.py wires ``add_parser`` and ``run`` in; errors are LagrangeGenError (one line, no traceback).
Output paths are checked before integrating (known suffix, a directory that can be written); if
writing still fails after the run, the trajectory is saved to a temporary file and the error
names it, so a finished run is never lost. Warnings (energy, projected initial state) are one
line each on stderr.
"""

from __future__ import annotations

import argparse
import os
import tempfile
from pathlib import Path

from ..errors import SimulationError
from ..jit.portable import JIT_MODES
from .options import (BUILD, NUMBER, method_name, one_line_warnings, out_dir, parse_assignments,
                      parse_times, velocity_names)
from ..steppers.core.method_spec import SETTING_HELP
from ..steppers.core.registry import INFO, METHODS

OUT_SUFFIXES = (".npz", ".csv")
PLOT_SUFFIXES = (".png", ".pdf", ".svg")


def add_parser(subparsers):
    """Add the ``simulate`` subcommand to an argparse subparsers object."""
    methods = "\n".join(f"  {m:27s} order {INFO[m].order}, {INFO[m].summary}" for m in METHODS)
    p = subparsers.add_parser(
        "simulate", help="integrate a model with one of the steppers",
        description="Integrate a model file (generated into --gen-dir when missing or stale) or a "
                    "generated module; print a summary, optionally write the trajectory (.npz or "
                    ".csv) and a plot (.png). A method's settings are options named after its "
                    "settings record; an option the method does not have is refused.",
        epilog="methods:\n" + methods, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("model", metavar="MODEL.py", help="model file or generated module")
    p.add_argument("--method", default="midpoint",
                   help="stepper (default: midpoint; the list below)")
    p.add_argument("--h", type=float,
                   help="step size (required by the fixed-step methods; adaptive: first step)")
    p.add_argument("--t-end", type=float, required=True, help="final time")
    p.add_argument("--t0", type=float, default=0.0, help="initial time (default 0)")
    p.add_argument("--q0", type=float, nargs="+", metavar="Q",
                   help="initial coordinates (default 0)")
    p.add_argument("--v0", type=float, nargs="+", metavar="V",
                   help="initial velocities (default 0)")
    p.add_argument("--param", action="append", default=[], metavar="NAME=VALUE,...",
                   help="parameter values, e.g. k=20,m=0.5; repeatable (default: the model's "
                        "defaults)")
    p.add_argument("--set", action="append", metavar="NAME=VALUE,...", dest="options",
                   help="options passed to the model file's build() (e.g. n=8), repeatable")
    p.add_argument("--keep", action="append", metavar="NAME,...",
                   help="constrained models: velocities (e.g. theta_dot) whose v0 is kept when "
                        "v0 is projected onto J v = 0; the others are solved for")
    p.add_argument("--penetration", choices=("project", "refuse", "keep"), default="project",
                   help="contact methods, q0 inside a contact (a gap < 0): project it out "
                        "(default, no energy added), refuse, or keep it there; warned in one "
                        "line either way")
    p.add_argument("--save-every", type=int, default=1, metavar="K", help="keep every K-th state")
    p.add_argument("--t-eval", nargs="+", metavar="T",
                   help="adaptive methods: save the states at these times, each a number or a "
                        "range START:STOP:STEP (STOP included), e.g. 0:10:0.01 (default: every "
                        "step)")
    p.add_argument("--out", metavar="FILE", help="write the trajectory (.npz or .csv)")
    p.add_argument("--plot", metavar="FILE.png",
                   help="plot coordinates and energy error (.png, .pdf or .svg)")
    p.add_argument("--gen-dir", metavar="DIR",
                   help="where model files are generated (default: as lagrange-gen's -o, "
                        "generated/ beside the model file or its models/ folder)")
    p.add_argument("--progress", action="store_true", help="show a progress bar on stderr")
    p.add_argument("--jit", choices=JIT_MODES,
                   help="compiled loop: specialized (the model's kernels inlined: fastest steps, "
                        "compiled per model on first use), portable (the stepper compiled once "
                        "for every model: a new model compiles only its kernels), auto "
                        "(default, or $LAGRANGE_GEN_JIT: specialized when cached, else "
                        "portable, switching to specialized during a long run)")
    add_setting_options(p)
    p.add_argument("--force", action="store_true",
                   help="regenerate the module even when the one on disk comes from another model "
                        "file or was generated with another freeze or build options")
    return p


def _setting_fields():
    """{field: (default, methods having it)} over every method's settings record, in order."""
    fields = {}
    for m in METHODS:
        record = INFO[m].settings
        for name in record._fields:
            fields.setdefault(name, (record._field_defaults[name], []))[1].append(m)
    return fields


def add_setting_options(p):
    """One option per settings field of any method (--newton-tol, --compliance, --rtol, ...):
    read from the methods' specs, so a new method's settings need no edit here. Every option
    defaults to None: only what the user gives reaches simulate."""
    group = p.add_argument_group("method settings (each applies to the methods listed)")
    for name, (default, methods) in _setting_fields().items():
        which = ", ".join(methods) if len(methods) < len(METHODS) else "every method"
        text = f"{SETTING_HELP.get(name, name)} [{which}; default {default}]"
        flag = "--" + name.replace("_", "-")
        if isinstance(default, bool):
            group.add_argument(flag, action="store_true", default=None, help=text)
        elif isinstance(default, tuple):
            group.add_argument(flag, type=float, nargs=len(default), default=None, help=text)
        else:
            group.add_argument(flag, type=type(default), default=None, help=text)


def given_settings(args):
    """{field: value} of the settings options the user gave."""
    given = {name: getattr(args, name) for name in _setting_fields()}
    return {name: tuple(v) if isinstance(v, list) else v for name, v in given.items()
            if v is not None}


def parse_params(pairs):
    """--param values (a list of 'a=1,b=2') -> {name: float}; SimulationError when malformed."""
    return parse_assignments(pairs, "--param", NUMBER, SimulationError)


def _vector(values):
    return "[" + ", ".join(f"{x:.9g}" for x in values) + "]"


def check_output_path(option, path, suffixes):
    """Before the run: a known suffix, not a directory, and a directory (or the nearest existing
    ancestor, which the writers create below) in which a file can actually be created."""
    target = Path(path)
    if target.suffix not in suffixes:
        raise SimulationError(f"{option} {path}: use a {' or '.join(suffixes)} file name")
    if target.is_dir():
        raise SimulationError(f"{option} {path}: is a directory")
    parent = target.parent
    while not parent.exists() and parent != parent.parent:
        parent = parent.parent
    if not parent.is_dir():
        raise SimulationError(f"{option} {path}: {parent} is not a directory")
    if target.exists() and not os.access(target, os.W_OK):
        raise SimulationError(f"{option} {path}: the file is not writable")
    try:
        with tempfile.TemporaryFile(dir=parent):
            pass
    except OSError as exc:
        raise SimulationError(f"{option} {path}: cannot create files in {parent} "
                              f"({exc.strerror or exc})") from None


def run(args) -> int:
    """Run the subcommand; returns the exit status."""
    from ..run.simulate import load_module, simulate
    method_name(args.method, SimulationError)
    if args.out:
        check_output_path("--out", args.out, OUT_SUFFIXES)
    if args.plot:
        check_output_path("--plot", args.plot, PLOT_SUFFIXES)
    params = parse_params(args.param)
    t_eval = None if args.t_eval is None else parse_times(args.t_eval, "--t-eval",
                                                          SimulationError)
    options = parse_assignments(args.options, "--set", BUILD, SimulationError)
    keep = velocity_names(args.keep)
    gen_dir = out_dir(args.model, args.gen_dir)
    with one_line_warnings():       # one line each, also when the run then fails
        model = args.model
        if options:
            model = load_module(model, gen_dir, args.method, args.force, options=options)
        traj = simulate(model, args.method, args.q0, args.v0, t_end=args.t_end,
                        h=args.h, params=params, save_every=args.save_every,
                        t_eval=t_eval, t0=args.t0, progress=args.progress,
                        out_dir=gen_dir, force=args.force, keep=keep, jit=args.jit,
                        penetration=args.penetration, **given_settings(args))
    _summary(traj)
    _write_outputs(traj, args.out, args.plot)
    return 0


def _summary(traj):
    per_step = traj.wall_time / max(traj.n_steps, 1)
    kind = "mean h" if traj.step_counts else "h"
    tolerances = "".join(f", {name} {traj.settings[name]:g}" for name in ("rtol", "atol")
                         if traj.step_counts and name in traj.settings)
    print(f"model {traj.model}, method {traj.method}{tolerances}, {kind} = {traj.h:g}, "
          f"{traj.n_steps} steps to t = {traj.t[-1]:.9g}")
    if traj.step_counts:
        print("adaptive: " + ", ".join(f"{k} {v}" for k, v in traj.step_counts.items()))
    for event in traj.events[:10]:
        print(f"event {event}")
    print(f"wall time {traj.wall_time:.3f} s ({per_step * 1e9:.0f} ns/step), "
          f"compile/load {traj.compile_time:.2f} s ({traj.jit} loop)")
    print(f"final q = {_vector(traj.q[-1])}, v = {_vector(traj.v[-1])}")
    contact_work = traj.saved.get("contact_work")
    if contact_work is not None:     # impacts and friction: E changes by the impulses' work
        work = contact_work[:, 0] + (traj.work if traj.work is not None else 0.0)
        # event-driven runs hold persistent contacts by forces, whose work W also counts
        what = ("the contact impulses and of the persistent contacts' forces"
                if "impacts" in traj.saved else "the contact impulses")
        forces = " and of the other forces" if traj.work is not None else ""
        balance = float(abs(traj.energy_error - work).max())
        print(f"max |E - E0 - W| = {balance:.3e} (E0 = {traj.energy[0]:.9g}, W the work of "
              f"{what}{forces}, final W = {work[-1]:.6g})")
        impacts = traj.impacts
        if "impacts" in traj.saved:      # event-driven: the located impacts
            shown = ", ".join(f"t = {row['t']:.9g} (contact {row['contact']}, p_N = "
                              f"{row['normal']:.6g})" for row in impacts[:3])
            print(f"impacts: {int(traj.saved['impacts'][-1, 0])}"
                  + (f"; first {shown}" if shown else ""))
    elif traj.work is None:
        print(f"max |E - E0| = {traj.max_energy_error:.3e} (E0 = {traj.energy[0]:.9g})")
    else:       # forced, damped or rheonomic: E changes by the work W done on the system
        print(f"max |E - E0 - W| = {traj.max_energy_balance_error:.3e} (E0 = {traj.energy[0]:.9g}, "
              f"final W = {traj.work[-1]:.6g})")
    if traj.constraint_names:
        print(f"max |Phi| = {traj.constraint_error.max():.3e}, "
              f"max |J v| = {traj.velocity_constraint_error.max():.3e}")
    # the fixed-step contact methods count their solver's sweeps there (an adaptive run: steps)
    if traj.newton_iters.sum() and not traj.step_counts:
        what = "Gauss-Seidel sweeps" if contact_work is not None else "Newton iterations"
        print(f"{what} per step: {traj.newton_iters.sum() / max(traj.n_steps, 1):.2f}")


def _write_outputs(traj, out, plot):
    """Write --out, then --plot. A failure here comes after a finished run: any exception of the
    writers (OSError, but also matplotlib's or numpy's own) becomes one line that says where the
    trajectory is, saved to a temporary .npz when --out was not written."""
    saved = None
    if out:
        try:
            (traj.to_npz if out.endswith(".npz") else traj.to_csv)(out)
            print(f"wrote {out}")
            saved = out
        except Exception as exc:  # noqa: BLE001 -- see the docstring
            raise SimulationError(f"--out {out}: writing failed after the run ({_reason(exc)}); "
                                  f"{_rescue(traj)}") from None
    if plot:
        try:
            traj.plot(plot)
            print(f"wrote {plot}")
        except Exception as exc:  # noqa: BLE001 -- see the docstring
            where = f"the trajectory is in {saved}" if saved else _rescue(traj)
            raise SimulationError(f"--plot {plot}: writing failed after the run "
                                  f"({_reason(exc)}); {where}") from None


def _rescue(traj):
    """Save the trajectory to a new temporary .npz; returns the sentence saying where (or
    that it is lost)."""
    try:
        fd, path = tempfile.mkstemp(prefix=f"lagrange-gen-{traj.model}-", suffix=".npz")
        os.close(fd)
        traj.to_npz(path)
    except Exception as exc:  # noqa: BLE001 -- the last resort must not raise
        return f"saving it to a temporary file failed too ({_reason(exc)}): the trajectory is lost"
    return f"the trajectory was saved to {path} instead"


def _reason(exc):
    return f"{type(exc).__name__}: {exc}".replace("\n", " ")
