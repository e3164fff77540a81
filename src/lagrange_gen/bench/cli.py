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
    from ..analysis.nonsmooth_experiments import run_nonsmooth_report
    print(run_nonsmooth_report(args.reports, args.models))


def _suite_kwargs(args):
    return dict(models_dir=args.models, reports_dir=args.reports, quick=args.quick,
                progress=not args.no_progress)


def _precision(args):
    from .precision import run_precision
    print(run_precision(**_suite_kwargs(args))["report"])


def _stability(args):
    from .stability import run_stability
    print(run_stability(**_suite_kwargs(args))["report"])


def _hard(args):
    from .hard import run_hard
    print(run_hard(**_suite_kwargs(args))["report"])


def _report(args):
    from .report import run_report
    print(run_report(**_suite_kwargs(args))["report"])


def _constraints(args):
    from .constraints import run_constraints_bench
    run_constraints_bench(Path(args.reports) / "constraints.md", quick=args.quick, models_dir=args.models)


def _scale(args):
    from .scale import run_scale_bench
    run_scale_bench(args.models, args.reports, quick=args.quick)


def _speed(args):
    from .speed import run_speed_bench
    print(run_speed_bench(args.models, reports_dir=args.reports, quick=args.quick)["report"])


def _robots(args):
    from .robots import run_robots_bench
    print(run_robots_bench(args.models, args.reports, quick=args.quick)["report"])


def _ensemble(args):
    from .ensemble import run_ensemble_bench
    run_ensemble_bench(Path(args.reports) / "ensemble.md", models_dir=args.models, quick=args.quick)


def _gpu(args):
    from .gpu import run_gpu_bench
    run_gpu_bench(Path(args.reports) / "gpu.md", models_dir=args.models, quick=args.quick)


def _stepapi(args):
    from .stepapi import run_stepapi_bench
    run_stepapi_bench(Path(args.reports) / "stepapi.md", models_dir=args.models, quick=args.quick)


def _compile(args):
    from .compile import run_compile_bench
    print(run_compile_bench(Path(args.reports) / "compile.md", progress=not args.no_progress))


def _firstrun(args):
    from .firstrun import run_firstrun_bench
    command = "lagrange-gen bench firstrun" + (" --quick" if args.quick else "")
    print(run_firstrun_bench(args.models, args.reports, quick=args.quick,
                             progress=not args.no_progress, command=command)["report"])


def _contact(args):
    from .contact import run_contact
    print(run_contact(**_suite_kwargs(args))["report"])


def _gradients(args):
    from .gradients import run_gradients_bench
    print(run_gradients_bench(args.models, args.reports, quick=args.quick)["report"])


def _harness(args):
    from .harness import run_harness_bench
    run_harness_bench(args.reports, thorough=not args.quick)


SUITES = {
    "pipeline": ("derive/emit/compile/cached-import times vs sympy.physics.mechanics", _pipeline),
    "steppers": ("ns per step of every method vs hand-written numba loops", _steppers),
    "nonsmooth": ("the lecture's Prandtl/play/Coulomb experiments with cycle figures", _nonsmooth),
    "precision": ("work-precision diagrams of every stepper vs scipy and sympy.mechanics", _precision),
    "stability": ("tau = h omega spectral-radius curves, largest stable h per hard case", _stability),
    "hard": ("HARD_CASES 3-8 with pass/fail verdicts against their references", _hard),
    "report": ("precision + stability + hard, and the method-choice summary", _report),
    "constraints": ("linkage drift per method, rattle vs verlet cost, breaking stiffness", _constraints),
    "scale": ("n-link pendulum n = 1..32: derive/emit/compile/step cost vs sympy LagrangesMethod", _scale),
    "speed": ("the speed goals in one run: vs PyDy at equal error, hand loops, MuJoCo, cold start",
              _speed),
    "robots": ("UR5, 8/12/24-link spatial chains, 30-DoF tree: pipeline, forward dynamics and its "
               "derivatives against Pinocchio (pin)", _robots),
    "ensemble": ("members per second of lagrange_gen.ensemble on 1 and 2 threads vs a simulate loop",
                 _ensemble),
    "gpu": ("member-steps/s of ensemble(device='cuda') vs the CPU ensemble, max difference, "
            "compile time; says so when no GPU is present", _gpu),
    "stepapi": ("us per Stepper.step call on the cart pole vs simulate per step; controller hook cost",
                _stepapi),
    "compile": ("first compile with each numba speedup on and off (LAGRANGE_GEN_SPEEDUPS)",
                _compile),
    "firstrun": ("CPU seconds from model file to first step (empty caches, warm library, native "
                 "kernels on and off), the goals of issue 40, cost per call once compiled",
                 _firstrun),
    "contact": ("work-precision of moreau_jean, spook_contacts and dop853_impacts on the bouncing "
                "ball and the rocking block against closed forms (Siconos when installed)",
                _contact),
    "gradients": ("forward sensitivities: cost against the plain run for k parameters and q0/v0, "
                  "agreement with central differences of simulate", _gradients),
    "harness": ("differential harness, thorough profile (--quick: CI profile); repository checkout only", _harness),
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
    p.add_argument("--no-progress", action="store_true",
                   help="no progress bar (precision, stability, hard, report)")
    return p


def run(args) -> int:
    import os
    from ..jit.portable import JIT_ENV
    # The suites time the specialized loops (the production speed of a model run more than once)
    # unless the environment asks otherwise; bench speed's first-use rows pass jit themselves.
    os.environ.setdefault(JIT_ENV, "specialized")
    SUITES[args.suite][1](args)
    return 0
