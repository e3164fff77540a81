"""`lagrange-gen examples [NAME] [--to DIR]`: the example model files, listed or copied.

The examples are the repository's models/*.py. A built package carries them as package data in
lagrange_gen/example_models/ (setup.py copies them there when it builds); a checkout (an
editable install) reads models/ itself. cli/main.py wires ``add_parser`` and ``run`` in.
"""

from __future__ import annotations

import ast
import difflib
import shutil
from pathlib import Path

from ..errors import LagrangeGenError

#: The folder of the examples inside the package, filled by setup.py's build step.
PACKAGED = "example_models"


def examples_dir(package=None) -> Path:
    """The folder holding the example model files: ``package``/example_models (``package``:
    the lagrange_gen folder, default this one's) when the build put them there, else the
    checkout's models/ folder beside src/."""
    package = Path(__file__).resolve().parent.parent if package is None else Path(package)
    packaged = package / PACKAGED
    if packaged.is_dir():
        return packaged
    return package.parent.parent / "models"


def example_files() -> dict:
    """{name: path} of every example model file, by name."""
    folder = examples_dir()
    return {p.stem: p for p in sorted(folder.glob("*.py")) if not p.name.startswith("_")}


def summary(path) -> str:
    """The first line of a model file's docstring (read, not run), or ""."""
    try:
        doc = ast.get_docstring(ast.parse(Path(path).read_text(encoding="utf-8")))
    except (OSError, SyntaxError, UnicodeDecodeError, ValueError):
        return ""
    return (doc or "").strip().splitlines()[0] if doc and doc.strip() else ""


def add_parser(subparsers):
    """Add the ``examples`` subcommand to an argparse subparsers object."""
    p = subparsers.add_parser(
        "examples", help="list the example model files, or copy one into a folder",
        description="Without NAME, list the example model files with their summaries; with "
                    "NAME, copy NAME.py into --to DIR (default: the working directory), ready "
                    "for `lagrange-gen DIR/NAME.py` and `lagrange-gen simulate DIR/NAME.py`.")
    p.add_argument("name", nargs="?", metavar="NAME",
                   help="the example to copy (e.g. cart_pendulum)")
    p.add_argument("--to", default=".", metavar="DIR",
                   help="folder to copy it into (created if missing; default: .)")
    p.add_argument("--force", action="store_true", help="overwrite a file of that name there")
    return p


def run(args) -> int:
    """List, or copy ``args.name``; LagrangeGenError (one line) for an unknown name or an
    existing file."""
    files = example_files()
    if not files:
        raise LagrangeGenError(f"no example model files in {examples_dir()} (a build of "
                               f"lagrange-gen without them)")
    if args.name is None:
        width = max(map(len, files))
        for name, path in files.items():
            print(f"{name:{width}s}  {summary(path)}")
        print(f"\ncopy one with: lagrange-gen examples NAME --to DIR ({len(files)} examples)")
        return 0
    name = args.name[:-3] if args.name.endswith(".py") else args.name
    if name not in files:
        near = difflib.get_close_matches(name, list(files), n=3)
        hint = f"did you mean {', '.join(near)}?" if near else f"known: {', '.join(files)}"
        raise LagrangeGenError(f"no example {name!r}: {hint} (lagrange-gen examples lists them)")
    target = Path(args.to) / f"{name}.py"
    if target.exists() and not args.force:
        raise LagrangeGenError(f"{target} exists: not overwritten (pass --force, or choose "
                               f"another --to DIR)")
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(files[name], target)
    except OSError as exc:
        raise LagrangeGenError(f"{target}: cannot copy the example there "
                               f"({exc.strerror or exc})") from None
    print(f"wrote {target}: generate it with `lagrange-gen {target}`, run it with "
          f"`lagrange-gen simulate {target} --method midpoint --h 1e-3 --t-end 10`")
    return 0
