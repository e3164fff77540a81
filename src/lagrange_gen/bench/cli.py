"""`lagrange-gen bench SUITE`: run a measurement suite and write its report under reports/."""

from __future__ import annotations


def add_parser(subparsers):
    p = subparsers.add_parser("bench", help="measure speed and accuracy; writes reports/<suite>.md",
                              description="Run a benchmark suite and write reports/<suite>.md. "
                                          "Timings live here, never in tests.")
    p.add_argument("suite", choices=["pipeline", "steppers"],
                   help="pipeline: derive/emit/compile/cached-import times vs sympy.physics.mechanics; "
                        "steppers: ns per step of every method vs hand-written numba loops")
    p.add_argument("--reports", default="reports", metavar="DIR", help="report directory (default: reports)")
    p.add_argument("--models", default="models", metavar="DIR", help="model directory (default: models)")
    p.add_argument("--quick", action="store_true", help="smaller settings for CI smoke runs")
    return p


def run(args) -> int:
    from pathlib import Path
    if args.suite == "pipeline":
        from .pipeline import run_pipeline_bench
        run_pipeline_bench(args.models, Path(args.reports) / "pipeline.md")
    elif args.suite == "steppers":
        from .steppers import run_steppers_bench
        run_steppers_bench(Path(args.reports) / "steppers.md",
                           model_file=Path(args.models) / "cart_pendulum.py", quick=args.quick)
    return 0
