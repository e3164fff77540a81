"""`lagrange-gen bench SUITE`: run a measurement suite and write its report under reports/.

Each suite is one entry of SUITES: its help line and a runner taking the parsed arguments.
"""

from __future__ import annotations

from pathlib import Path


def _pipeline(args):
    from .pipeline import run_pipeline_bench
    run_pipeline_bench(args.models, Path(args.reports) / "pipeline.md")


def _steppers(args):
    from .steppers import run_steppers_bench
    run_steppers_bench(Path(args.reports) / "steppers.md",
                       model_file=Path(args.models) / "cart_pendulum.py", quick=args.quick)


def _nonsmooth(args):
    from ..nonsmooth.experiments import run_nonsmooth_report
    print(run_nonsmooth_report(args.reports, args.models))


SUITES = {
    "pipeline": ("derive/emit/compile/cached-import times vs sympy.physics.mechanics", _pipeline),
    "steppers": ("ns per step of every method vs hand-written numba loops", _steppers),
    "nonsmooth": ("the lecture's Prandtl/play/Coulomb experiments with cycle figures", _nonsmooth),
}


def add_parser(subparsers):
    p = subparsers.add_parser("bench", help="measure speed and accuracy; writes reports/<suite>.md",
                              description="Run a benchmark suite and write reports/<suite>.md. "
                                          "Timings live here, never in tests.")
    p.add_argument("suite", choices=sorted(SUITES),
                   help="; ".join(f"{name}: {text}" for name, (text, _) in sorted(SUITES.items())))
    p.add_argument("--reports", default="reports", metavar="DIR", help="report directory (default: reports)")
    p.add_argument("--models", default="models", metavar="DIR", help="model directory (default: models)")
    p.add_argument("--quick", action="store_true", help="smaller settings for CI smoke runs")
    return p


def run(args) -> int:
    SUITES[args.suite][1](args)
    return 0
