"""Pages made when the docs build (mkdocs-gen-files runs this script; mkdocs.yml names it).

- examples/<name>.md for every script in examples/: the script is run (from the repository
  root, with an output folder as its one argument) and its page shows its docstring, what it
  printed, the figures it wrote and its source. A script that fails fails the build, so the
  pages cannot go stale.
- reference/cli.md: the `--help` of the lagrange-gen command and of each subcommand.
- reference/kernels.md: the kernels a generated module may hold and their arguments
  (lagrange_gen.jit.kernel_abi.ARGUMENTS).
- reports/: the reports `lagrange-gen bench` writes (and their figures), so the guides link
  to them.
"""
import ast
import logging
import os
import pathlib
import subprocess
import sys
import tempfile
import time

import mkdocs_gen_files

ROOT = pathlib.Path(__file__).resolve().parents[1]
EXAMPLE_TIMEOUT_S = 600
log = logging.getLogger("mkdocs.gen_pages")


def run_example(script, out_dir):
    """Run ``script`` from the repository root; its stdout, or RuntimeError (failing the
    build) naming the script with the end of its stderr."""
    # no detached background compile (jit/first_run.py) outliving the build
    env = dict(os.environ, MPLBACKEND="Agg", LAGRANGE_GEN_BACKGROUND_COMPILE="0")
    start = time.perf_counter()
    done = subprocess.run([sys.executable, str(script), str(out_dir)], cwd=ROOT, env=env,
                          capture_output=True, text=True, timeout=EXAMPLE_TIMEOUT_S)
    log.info("example %s ran in %.1f s", script.name, time.perf_counter() - start)
    if done.returncode != 0:
        tail = "\n".join(done.stderr.strip().splitlines()[-15:])
        raise RuntimeError(f"examples/{script.name} failed (exit {done.returncode}):\n{tail}")
    return done.stdout


def title_and_summary(script):
    """An example's title and one-line summary from its docstring, whose first paragraph reads
    "Title: what it shows. ..." (the title falls back to the file name)."""
    doc = ast.get_docstring(ast.parse(script.read_text())) or ""
    first = " ".join(doc.split("\n\n")[0].split())
    title, colon, rest = first.partition(": ")
    if not colon or len(title) > 40:
        title, rest = script.stem.replace("_", " "), first
    return title, rest.split(". ")[0].rstrip(".") + "."


def example_page(script, stdout, figures):
    source = script.read_text()
    doc = ast.get_docstring(ast.parse(source)) or ""
    title, _ = title_and_summary(script)
    lines = [f"# {title}", "", doc, "",
             f"Source: `examples/{script.name}` (run from the repository root; this page ran it "
             "when the docs were built).", ""]
    for figure in figures:
        lines += [f"![{script.stem}]({figure.name})", ""]
    if stdout.strip():
        lines += ["What it printed:", "", "```text", stdout.rstrip(), "```", ""]
    lines += ["```python", source.rstrip(), "```", ""]
    return "\n".join(lines)


def write_examples():
    scripts = sorted((ROOT / "examples").glob("*.py"))
    index = ["# Examples", "",
             "Each example is a script in `examples/`, run when these pages are built: the "
             "figures and printed output below are from that run. Run one yourself from the "
             "repository root with `python examples/NAME.py [OUT_DIR]` (figures go to `out/` by "
             "default).", ""]
    with tempfile.TemporaryDirectory() as tmp:
        for script in scripts:
            out_dir = pathlib.Path(tmp) / script.stem
            out_dir.mkdir()
            stdout = run_example(script, out_dir)
            figures = sorted(out_dir.glob("*.png"))
            for figure in figures:
                with mkdocs_gen_files.open(f"examples/{figure.name}", "wb") as f:
                    f.write(figure.read_bytes())
            with mkdocs_gen_files.open(f"examples/{script.stem}.md", "w") as f:
                f.write(example_page(script, stdout, figures))
            title, summary = title_and_summary(script)
            index.append(f"- [{title}]({script.stem}.md) (`examples/{script.name}`): {summary}")
    with mkdocs_gen_files.open("examples/index.md", "w") as f:
        f.write("\n".join(index) + "\n")


def write_cli_help():
    lines = ["# Command-line reference", "",
             "The `--help` of `lagrange-gen` and of each subcommand, as printed by this version "
             "(the [CLI guide](../guides/cli.md) explains them with examples).", ""]
    from lagrange_gen.cli.main import SUBCOMMANDS
    env = dict(os.environ, COLUMNS="100")
    for command in ("", *SUBCOMMANDS):
        argv = [sys.executable, "-m", "lagrange_gen.cli", *([command] if command else []), "--help"]
        done = subprocess.run(argv, cwd=ROOT, env=env, capture_output=True, text=True, timeout=120)
        if done.returncode != 0:
            raise RuntimeError(f"lagrange-gen {command} --help failed:\n{done.stderr}")
        lines += [f"## lagrange-gen {command}".rstrip(), "", "```text", done.stdout.rstrip(),
                  "```", ""]
    with mkdocs_gen_files.open("reference/cli.md", "w") as f:
        f.write("\n".join(lines))


def write_kernel_table():
    from lagrange_gen.jit.kernel_abi import ARGUMENTS
    lines = ["# Kernels of a generated module", "",
             "Every kernel a generated module may define, with its arguments in order "
             "(`lagrange_gen.jit.kernel_abi.ARGUMENTS`; sizes: n coordinates, m holonomic "
             "constraints, r nonholonomic constraints, c contacts, ne nonsmooth elements, and "
             "the counts of parameters, events, inputs and outputs). A module holds the kernels "
             "its model and methods need; its docstring lists them and why. Output arrays are "
             "filled in place; `energy` returns a float. The [generated modules guide]"
             "(../guides/generated-modules.md) says what each computes.", "",
             "| kernel | arguments (shape) |", "|---|---|"]
    for name, arguments in ARGUMENTS.items():
        shown = ", ".join(arg if shape is None else f"{arg} ({', '.join(shape)})"
                          for arg, shape in arguments)
        lines.append(f"| `{name}` | {shown} |")
    with mkdocs_gen_files.open("reference/kernels.md", "w") as f:
        f.write("\n".join(lines) + "\n")


def copy_reports():
    for path in sorted((ROOT / "reports").iterdir()):
        if path.suffix in (".md", ".png"):
            with mkdocs_gen_files.open(f"reports/{path.name}", "wb") as f:
                f.write(path.read_bytes())


copy_reports()
write_kernel_table()
write_cli_help()
write_examples()
