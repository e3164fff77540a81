"""Command line: `lagrange-gen MODEL.py ...` generates; subcommands simulate and bench.

The CLI only chains the pipeline stages; every user error is one line on stderr and a non-zero
exit (``--debug`` shows the traceback).
"""

from __future__ import annotations

import argparse
import os
import sys
import time

from ..errors import LagrangeGenError
from .options import BUILD, NUMBER, one_line_warnings, out_dir, parse_assignments

SUBCOMMANDS = ("simulate", "sweep", "bench", "identify", "equations", "animate", "examples", "urdf")

_EPILOG = """\
examples:
  lagrange-gen examples                           list the example model files
  lagrange-gen examples cart_pendulum --to models copy one into models/
  lagrange-gen urdf ur5.urdf -o models/ur5_robot.py   a model file from a robot's URDF
  lagrange-gen models/cart_pendulum.py            write generated/cart_pendulum.py
  lagrange-gen models/*.py                        every model
  lagrange-gen models/n_link_pendulum.py --set n=8
  lagrange-gen --check models/*.py                exit 1 if a generated file is missing or stale
  lagrange-gen --methods verlet,midpoint models/double_pendulum.py
  lagrange-gen --freeze g=9.81,l=1 models/n_link_pendulum.py --set n=16
  lagrange-gen simulate models/cart_pendulum.py --method midpoint --h 1e-3 --t-end 10
  lagrange-gen simulate models/n_link_pendulum.py --set n=4 --method rk4 --h 1e-3 --t-end 5
  lagrange-gen equations models/cart_pendulum.py [--latex]   print H, h, g, Q (Phi, J, gamma)
  lagrange-gen sweep models/cart_pendulum.py --method rk4 --h 1e-3 --t-end 10 \\
      --grid k=1:100:50 --grid m=0.1:1:20 --out sweep.npz --plot sweep.png
  lagrange-gen bench --help
  lagrange-gen identify cycle.csv --kind prandtl --elements 3
  lagrange-gen animate traj.npz --out traj.gif    the model's draw= along a saved run

A model file builds a lagrange_gen.Model from SymPy expressions and assigns it to `model`
(`lagrange-gen examples cart_pendulum` copies one to start from). The generated module holds
numba kernels (dynamics, energy, Jacobians, constraints), forward dynamics and one run_<method>
function per stepper; import it, or use `lagrange-gen simulate`. Generated modules go to
generated/ beside a models/ folder, else beside the model file, from any working directory.
"""


def generate_parser():
    p = argparse.ArgumentParser(
        prog="lagrange-gen",
        description="Derive equations of motion from SymPy model files and write numba kernels "
                    "into generated/ (see -o). Subcommands: simulate, sweep, equations, "
                    "examples, urdf, bench, identify, animate (lagrange-gen SUBCOMMAND --help).",
        epilog=_EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("models", nargs="+", metavar="MODEL.py", help="model files (e.g. models/*.py)")
    p.add_argument("-o", "--out-dir", "--gen-dir", metavar="DIR", dest="out_dir",
                   help="directory for generated modules (default, from any working directory: "
                        "generated/ beside the folder of a model file in a folder named models/, "
                        "else generated/ beside the model file)")
    p.add_argument("--check", action="store_true",
                   help="write nothing; exit 1 when a generated file is missing or stale")
    p.add_argument("--methods", metavar="M1,M2",
                   help="emit glue only for these steppers (default: all)")
    p.add_argument("--freeze", action="append", metavar="NAME=VALUE,...",
                   help="fold these parameters into the kernels as constants (e.g. g=9.81,l=1); "
                        "they leave PARAMS and cannot be passed at run time; repeatable")
    p.add_argument("--sensitivities", action="store_true",
                   help="also emit the parameter derivatives of the kernels that forward "
                        "sensitivities need (simulate(..., sensitivities=[...]); see "
                        "docs/guides/gradients.md)")
    p.add_argument("--set", action="append", metavar="NAME=VALUE,...", dest="options",
                   help="options passed to the model file's build() (e.g. n=8), repeatable")
    p.add_argument("--force", action="store_true",
                   help="derive and write again even when the generated file is current (an "
                        "unchanged model file, and unchanged files it reads or imports, is "
                        "otherwise not run again), and overwrite a generated file even when it "
                        "was generated from another model file with the same model name (or was "
                        "not written by lagrange-gen)")
    p.add_argument("--debug", action="store_true", help="show tracebacks")
    return p


def run_generate(args) -> int:
    """Generate (or --check) every model file given: a failing model is one line on stderr and
    does not stop the others; with several files, a last line lists the failed ones. Exit 2 if
    any failed, 1 if any is missing or stale (--check)."""
    from ..errors import GenerationError
    methods = args.methods.split(",") if args.methods else None
    options = parse_assignments(args.options, "--set", BUILD)
    freeze = parse_assignments(args.freeze, "--freeze", NUMBER, GenerationError)
    action = _check_one if args.check else _generate_one
    outcomes = [for_each_model(path, args.debug, action, path, args, methods, options, freeze)
                for path in args.models]
    failed = [str(path) for path, ok in zip(args.models, outcomes) if ok is None]
    if failed and len(args.models) > 1:
        print(f"lagrange-gen: {len(failed)} of {len(args.models)} model files failed: "
              f"{', '.join(failed)}", file=sys.stderr)
    return 2 if failed else 1 if False in outcomes else 0


def _generate_one(path, args, methods, options, freeze):
    start, where = time.perf_counter(), out_dir(path, args.out_dir)
    if not args.force:
        # decided before codegen.generated_files is imported: a current module costs no sympy
        from ..codegen.model_cache import generation_current
        target = generation_current(path, where, methods, options, freeze, args.sensitivities)
        if target is not None:
            print(f"{target} is current: not derived again ({time.perf_counter() - start:.2f} s; "
                  "--force derives it again)")
            return True
    from ..codegen.generated_files import generate_model
    result = generate_model(path, where, methods, options, freeze, force=args.force,
                            sensitivities=args.sensitivities)
    what = "written" if result.written else "unchanged"
    print(f"{result.path}: {what} ({time.perf_counter() - start:.2f} s, key {result.key[:12]})")
    return True


def _check_one(path, args, methods, options, freeze):
    from ..codegen.generated_files import check_generated
    from ..codegen.keys import regeneration_command
    where = out_dir(path, args.out_dir)
    target, problem = check_generated(path, where, methods, options, freeze, args.sensitivities)
    if problem is None:
        print(f"{target}: current")
        return True
    command = regeneration_command(path, where, options, methods, freeze, args.sensitivities)
    print(f"{target}: {problem}; run {command}")
    return False


def for_each_model(path, debug, action, *args):
    """``action(*args)`` for one model file; any failure but Ctrl-C is one line on stderr naming
    ``path`` and returns None (so the caller goes on with the next model); --debug re-raises."""
    try:
        return action(*args)
    except KeyboardInterrupt:
        raise
    except BaseException as exc:       # SystemExit from a model file too: it must not end the loop
        if debug:
            raise
        print(f"lagrange-gen: error: {_failure_line(path, exc)}", file=sys.stderr)
        return None


def _failure_line(path, exc) -> str:
    if isinstance(exc, SystemExit):
        return f"{path}: the model file called sys.exit({exc.code!r})"
    message = str(exc).strip().splitlines()[0] if str(exc).strip() else ""
    if not isinstance(exc, LagrangeGenError):
        message = f"{type(exc).__name__}: {message} (an internal error: --debug shows the traceback)"
    return message if str(path) in message else f"{path}: {message}"


def _subcommand_parser(name):
    p = argparse.ArgumentParser(prog="lagrange-gen")
    sub = p.add_subparsers(dest="command", required=True)
    if name == "simulate":
        from .simulate import add_parser
    elif name == "sweep":
        from .sweep import add_parser
    elif name == "identify":
        from ..identify.cli import add_parser
    elif name == "equations":
        from .equations import add_parser
    elif name == "animate":
        from .animate import add_parser
    elif name == "examples":
        from .examples import add_parser
    elif name == "urdf":
        from .urdf import add_parser
    else:
        from ..bench.cli import add_parser
    add_parser(sub)
    return p


def _run_subcommand(args) -> int:
    if args.command == "simulate":
        from .simulate import run
    elif args.command == "sweep":
        from .sweep import run
    elif args.command == "identify":
        from ..identify.cli import run
    elif args.command == "equations":
        from .equations import run
    elif args.command == "animate":
        from .animate import run
    elif args.command == "examples":
        from .examples import run
    elif args.command == "urdf":
        from .urdf import run
    else:
        from ..bench.cli import run
    return run(args)


def main(argv=None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    debug = "--debug" in argv
    try:
        with one_line_warnings():
            return _dispatch(argv)
    except LagrangeGenError as exc:
        if debug:
            raise
        print(f"lagrange-gen: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("lagrange-gen: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:         # `lagrange-gen equations ... | head`: the reader left
        sys.stdout = open(os.devnull, "w")
        return 0


def _dispatch(argv):
    if argv and argv[0] in SUBCOMMANDS:
        argv = [a for a in argv if a != "--debug"]
        args = _subcommand_parser(argv[0]).parse_args(argv)
        return _run_subcommand(args)
    args = generate_parser().parse_args(argv)
    return run_generate(args)


if __name__ == "__main__":
    sys.exit(main())
