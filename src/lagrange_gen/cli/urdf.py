"""`lagrange-gen urdf ROBOT.urdf -o models/robot.py`: a model file from a robot's URDF.

The model file holds the URDF's joint table (model/urdf.py, model/joint_tree.py) and builds the
robot from it with sympy.physics.mechanics; edit it, then run `lagrange-gen models/robot.py`.
cli/main.py wires ``add_parser`` and ``run`` in.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

from ..errors import ModelError


def add_parser(subparsers):
    """Add the ``urdf`` subcommand to an argparse subparsers object."""
    p = subparsers.add_parser(
        "urdf", help="write a model file from a robot's URDF",
        description="Read ROBOT.urdf (revolute, continuous, prismatic, fixed and mimic joints; "
                    "meshes and damping are not read) and write a model file holding its "
                    "joint table, built into sympy.physics.mechanics bodies: a fixed base (or "
                    "--floating-base), gravity "
                    "-g along the base's z, one coordinate per moving joint named after it.")
    p.add_argument("urdf", metavar="ROBOT.urdf")
    p.add_argument("-o", "--out", metavar="FILE.py",
                   help="the model file to write (default: models/<robot name>.py)")
    p.add_argument("--no-mimic", action="store_true",
                   help="give mimic joints their own coordinates (as Pinocchio does by default)")
    p.add_argument("--floating-base", action="store_true",
                   help="the root link moves freely: six coordinates first (its origin x, y, z and "
                        "angles about its own x, y, z; one chart, singular at q_base_ry = +-pi/2)")
    p.add_argument("--limits", action="store_true",
                   help="the joints' <limit> lower and upper as contacts (for the contact methods)")
    p.add_argument("--g", type=float, default=9.81, help="the default of the parameter g (9.81)")
    p.add_argument("--force", action="store_true", help="overwrite an existing file")
    return p


def run(args) -> int:
    from ..model.urdf import make_identifier, model_file_text, read_urdf
    text = model_file_text(args.urdf, mimic=not args.no_mimic, g=args.g, limits=args.limits,
                           floating_base=args.floating_base)
    out = Path(args.out) if args.out else Path("models") / f"{make_identifier(read_urdf(args.urdf).name, set())}.py"
    if out.exists() and not args.force:
        raise ModelError(f"{out} exists: --force overwrites it")
    out.parent.mkdir(parents=True, exist_ok=True)
    # written whole or not at all
    fd, temporary = tempfile.mkstemp(dir=out.parent, prefix=f".{out.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(text)
        os.replace(temporary, out)
    except BaseException:
        os.unlink(temporary)
        raise
    print(f"{out}: written; next: lagrange-gen {out}")
    return 0
