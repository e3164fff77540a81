"""`lagrange-gen bench compile`: the first compile of representative kernels with each numba
speedup (lagrange_gen.jit.speedups) on and off, so that a speedup numba has caught up with can be
retired.

Every measurement runs in a fresh child process with empty numba and portable caches and
$LAGRANGE_GEN_SPEEDUPS set to the configuration: ``all``, ``-<name>`` (all but one) for each
speedup, ``none``. The child times only the compile (imports excluded). A speedup's ratio is
the time without it over the time with all: above 1 it still pays.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

#: (label, generated module, what the child compiles): "glue" the specialized run_midpoint
#: through a first simulate (kernels and stepper inlined), "kernels" the kernels the portable
#: midpoint reaches, compiled for the portable argument types.
CASES = (("cart pendulum, specialized midpoint glue", "cart_pendulum.py", "glue"),
         ("3-link pendulum, midpoint's kernels", "n_link_pendulum_3.py", "kernels"))

_CHILD = """
import json, sys, time
from lagrange_gen.run.loader import import_generated
mod = import_generated(sys.argv[1])
start = time.perf_counter()
if sys.argv[2] == "glue":
    from lagrange_gen.run.simulate import simulate
    q0 = [0.1] * mod.N_COORDS
    simulate(mod, "midpoint", q0, [0.0] * mod.N_COORDS, t_end=0.02, h=1e-2, jit="specialized")
else:
    from lagrange_gen.jit.portable import kernel_table
    kernel_table(mod, "midpoint")
print(json.dumps({"seconds": time.perf_counter() - start}))
"""


def configurations():
    """[(label, $LAGRANGE_GEN_SPEEDUPS)]: all, all but each speedup, none."""
    from ..jit.speedups import NAMES
    return [("all", "all")] + [(f"without {n}", f"-{n}") for n in NAMES] + [("none", "none")]


def measure(module_path, what, speedups, timeout=900) -> float:
    """Seconds of the first compile of ``what`` for ``module_path`` in a fresh process."""
    with tempfile.TemporaryDirectory() as numba_dir, tempfile.TemporaryDirectory() as glue_dir:
        # native kernels off: the kernels case measures numba's compile of them (jit/native.py
        # compiles them without numba, which no numba speedup touches)
        env = dict(os.environ, NUMBA_CACHE_DIR=numba_dir, LAGRANGE_GEN_PORTABLE_DIR=glue_dir,
                   LAGRANGE_GEN_SPEEDUPS=speedups, LAGRANGE_GEN_NATIVE="0")
        done = subprocess.run([sys.executable, "-c", _CHILD, str(module_path), what], env=env,
                              capture_output=True, text=True, timeout=timeout)
        if done.returncode != 0:
            raise RuntimeError(f"bench compile child failed: {done.stderr[-2000:]}")
        return json.loads(done.stdout.strip().splitlines()[-1])["seconds"]


def write_report(results, path, numba_version="?") -> str:
    """reports/compile.md from ``results`` {case label: {configuration label: seconds}}; a
    speedup's ratio is its "without" time over "all". Returns the text."""
    configs = [label for label, _ in configurations()]
    lines = ["# First compile with each numba speedup on and off", "",
             f"`lagrange-gen bench compile`, numba {numba_version}. Each cell: one fresh process, "
             "empty numba and portable caches, seconds of the compile alone. Ratio: without / "
             "all (above 1: the speedup still pays).", "",
             "| case | " + " | ".join(configs) + " |",
             "|---|" + "---:|" * len(configs)]
    for case, times in results.items():
        base = times.get("all")
        cells = []
        for label in configs:
            t = times.get(label)
            if t is None:
                cells.append("-")
            elif label == "all" or not base:
                cells.append(f"{t:.2f} s")
            else:
                cells.append(f"{t:.2f} s ({t / base:.2f}x)")
        lines.append(f"| {case} | " + " | ".join(cells) + " |")
    text = "\n".join(lines) + "\n"
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    Path(path).write_text(text)
    return text


def run_compile_bench(report_path, generated_dir="generated", progress=True) -> str:
    """Measure every case of CASES under every configuration and write the report."""
    from ..jit.speedups import numba_version
    results = {}
    for label, module, what in CASES:
        results[label] = {}
        for config, value in configurations():
            seconds = measure(Path(generated_dir) / module, what, value)
            results[label][config] = seconds
            if progress:
                print(f"{label}: {config}: {seconds:.2f} s", file=sys.stderr)
    return write_report(results, report_path, numba_version())
