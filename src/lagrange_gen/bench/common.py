"""Helpers shared by the precision, stability and hard suites: compiling the glue ahead in child
processes, a progress bar and markdown/figure output. Loading models, the guarded run and
the markdown table are lagrange_gen.analysis.runs.

Every run goes through :func:`lagrange_gen.run.simulate.simulate`, the path a user takes: its
``wall_time`` is the integration only (the glue is compiled or loaded from numba's cache before
the clock starts), and its exceptions are what a failed run looks like to a user.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

from ..analysis.runs import load_module, methods_for, model_available

ROOT = Path(__file__).resolve().parents[3]

#: The acceleration-level formulation is only ever shown as the bad example.
BAD_EXAMPLES = ("explicit_euler", "index1")


_COMPILE_CHILD = r"""
import json, sys
from lagrange_gen.errors import SimulationError
from lagrange_gen.run.simulate import simulate
for path, methods, q0 in json.loads(sys.argv[1]):
    for method in methods:
        try:
            simulate(path, method, q0, None, t_end=0.0, h=1e-3)
        except (SimulationError, ValueError, RuntimeError):
            pass    # refused start: the suite compiles this one itself
"""


def precompile(models_dir, gen_dir, stems, methods=None, workers=2):
    """Generate the modules of ``stems`` [(stem, options)] and compile the run_<method> glue of
    every method that applies to each in ``workers`` child processes: numba's cache is on disk,
    so the suites then load it instead of compiling one glue after another (about 3 s each,
    cold). The children run a zero-step simulate from a consistent start (same argument types
    as the suites' runs); with a warm cache they only load it."""
    from ..analysis.scenes import model_start
    jobs = []
    for stem, options in stems:
        if not model_available(models_dir, stem):
            continue
        mod = load_module(models_dir, stem, gen_dir, **options)
        for method in methods_for(mod, methods):
            jobs.append((mod.__file__, [method], model_start(mod).tolist()))
    bins = [jobs[i::max(1, workers)] for i in range(max(1, workers))]
    # Child processes started with -c, not multiprocessing: spawn would re-run the caller's
    # unguarded __main__, fork would copy numba's compiler state mid-flight.
    children = [subprocess.Popen([sys.executable, "-c", _COMPILE_CHILD, json.dumps(b)],
                                 stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
                for b in bins if b]
    for child in children:
        child.wait()


class Progress:
    """One-line text progress bar on stderr: ``[####    ] 12/40 label``; silent when disabled."""

    def __init__(self, total, title, enabled=True, width=30, stream=None):
        self.total, self.title, self.enabled = max(1, total), title, enabled
        self.width, self.done = width, 0
        self.stream = stream or sys.stderr

    def step(self, label="", count=1):
        """Count ``count`` items done (a sweep that stops early passes what it skipped)."""
        self.done += count
        if not self.enabled:
            return
        filled = self.width * min(self.done, self.total) // self.total
        text = f"\r{self.title} [{'#' * filled}{' ' * (self.width - filled)}] " \
               f"{self.done}/{self.total} {label[:40]:<40}"
        self.stream.write(text)
        self.stream.flush()

    def finish(self):
        """End the line (the total is an upper bound: sweeps stop early)."""
        if self.enabled:
            self.stream.write("\n")
            self.stream.flush()


def new_figure(*args, **kwargs):
    """matplotlib figure on the Agg backend (no display needed)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt.subplots(*args, **kwargs)


def save_figure(fig, path):
    import matplotlib.pyplot as plt
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return Path(path)


def write_report(path, lines):
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("\n".join(lines).rstrip() + "\n")
    return path


#: The final-state error at which the precision suite compares methods (its headline).
TARGET = 1e-8          # the headline's final-state error


def time_at(points, target=TARGET, key="final"):
    """Wall time at which a method's error (``key``) reaches ``target``, by log-log
    interpolation between the two runs that bracket it (points in sweep order: coarse to fine).
    None when no successful pair of consecutive runs brackets the target."""
    ok = [pt for pt in points if not pt.failed and getattr(pt, key) > 0]
    for a, b in zip(ok, ok[1:]):
        ea, eb = getattr(a, key), getattr(b, key)
        if ea >= target >= eb and ea > eb:
            w = (math.log(ea) - math.log(target)) / (math.log(ea) - math.log(eb))
            return math.exp((1 - w) * math.log(a.wall) + w * math.log(b.wall))
    first = ok[0] if ok else None
    if first is not None and getattr(first, key) <= target:
        return first.wall          # already below target at the coarsest setting: an upper bound
    return None


def by_method(points):
    """{method: its points, in sweep order}."""
    groups = {}
    for pt in points:
        groups.setdefault(pt.method, []).append(pt)
    return groups
