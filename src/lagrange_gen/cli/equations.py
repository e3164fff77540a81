"""`lagrange-gen equations MODEL.py [--latex]`: print the derived H, h, g, Q (and Phi, J, gamma
of a constrained model), the matrices of lagrange_gen.equations. cli/main.py wires it in."""

from __future__ import annotations

from .options import BUILD, parse_assignments


def add_parser(subparsers):
    p = subparsers.add_parser(
        "equations", help="print the derived equations of motion (H, h, g, Q, Phi, J, gamma)",
        description="Print H qddot + h + g = Q + J^T lambda, Phi(q) = 0 and J qddot = gamma of a "
                    "model file as derived (the matrices of lagrange_gen.equations).")
    p.add_argument("model", metavar="MODEL.py", help="model file")
    p.add_argument("--latex", action="store_true",
                   help="print LaTeX: the assembled equation H qddot + h + g = Q (+ J^T lambda, "
                        "Phi = 0, J qddot = gamma) in matrix form, one equation per line; large "
                        "models with their shared subexpressions after it")
    p.add_argument("--set", action="append", metavar="NAME=VALUE,...", dest="options",
                   help="options passed to the model file's build() (e.g. n=3), repeatable")
    p.add_argument("--no-simplify", action="store_true",
                   help="print the entries as derived, without simplifying the small ones")
    return p


def run(args) -> int:
    from ..derive.equations import equations
    eqs = equations(args.model, simplify=not args.no_simplify,
                    **parse_assignments(args.options, "--set", BUILD))
    print(eqs.latex() if args.latex else eqs)
    return 0
