"""Helpers shared by the precision, stability and hard suites: loading models, one guarded run
through the public ``simulate`` driver, which methods exist in this build, a progress bar and
markdown/figure output.

Every run goes through :func:`lagrange_gen.simulation.simulate`, the path a user takes: its
``wall_time`` is the integration only (the glue is compiled or loaded from numba's cache before
the clock starts), and its exceptions are what a failed run looks like to a user.
"""

from __future__ import annotations

import json
import subprocess
import sys
import time
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import EnergyWarning, SimulationError
from ..steppers import registry

ROOT = Path(__file__).resolve().parents[3]

#: Constrained methods of issue 4, used when a build registers them (registry.METHODS).
CONSTRAINED_NAMES = ("rattle", "constrained_midpoint", "constrained_implicit_euler", "spook",
                     "index1")
#: The acceleration-level formulation is only ever shown as the bad example.
BAD_EXAMPLES = ("explicit_euler", "index1")
NOT_AVAILABLE = "not available in this build"


def constrained_methods():
    """Constrained methods registered in this build, in registry order (maybe empty)."""
    named = getattr(registry, "CONSTRAINED_METHODS", CONSTRAINED_NAMES)
    return tuple(m for m in registry.METHODS if m in named)


def unconstrained_methods():
    """Methods for unconstrained smooth models: not the constrained or the nonsmooth ones."""
    skip = set(constrained_methods()) | set(registry.NONSMOOTH_METHODS)
    return tuple(m for m in registry.METHODS if m not in skip)


def has_method(name):
    return name in registry.METHODS


#: Glue methods of the modules the suites generate (None: every registered method). A subset
#: gives a different KEY, so only set it together with a private gen_dir.
GLUE_METHODS = None


def load_module(models_dir, stem, gen_dir, **options):
    """Generated module of models_dir/<stem>.py (generated into gen_dir when missing or stale)."""
    from ..loader import load
    return load(Path(models_dir) / f"{stem}.py", out_dir=gen_dir, methods=GLUE_METHODS,
                options=options or None)


_COMPILE_CHILD = r"""
import json, sys
from lagrange_gen.errors import SimulationError
from lagrange_gen.simulation import simulate
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
    from .scenes import model_start
    jobs = []
    for stem, options in stems:
        if not model_available(models_dir, stem):
            continue
        mod = load_module(models_dir, stem, gen_dir, **options)
        pool = constrained_methods() if mod.N_CONSTRAINTS else unconstrained_methods()
        for method in pool:
            if methods is None or method in methods:
                jobs.append((mod.__file__, [method], model_start(mod).tolist()))
    bins = [jobs[i::max(1, workers)] for i in range(max(1, workers))]
    # Child processes started with -c, not multiprocessing: spawn would re-run the caller's
    # unguarded __main__, fork would copy numba's compiler state mid-flight.
    children = [subprocess.Popen([sys.executable, "-c", _COMPILE_CHILD, json.dumps(b)],
                                 stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
                for b in bins if b]
    for child in children:
        child.wait()


def model_available(models_dir, stem):
    return (Path(models_dir) / f"{stem}.py").is_file()


def params_of(mod, **given):
    """Parameter vector (n_params,) in PARAMS order: defaults overridden by ``given``."""
    values = dict(zip(mod.PARAMS, mod.DEFAULTS))
    unknown = set(given) - set(values)
    if unknown:
        raise KeyError(f"{mod.NAME} has no parameter(s) {sorted(unknown)}")
    values.update(given)
    return np.array([values[name] for name in mod.PARAMS], dtype=np.float64)


@dataclass
class Run:
    """One guarded simulation: ``traj`` is the Trajectory, or None when it failed with ``error``
    (the exception's one-line message); ``wall`` is the best integration time in seconds, or the
    time to failure of a failed run."""

    traj: object
    wall: float
    error: str = ""
    fail_time: float = float("nan")     # simulated time of the failure (SimulationError.time)

    @property
    def ok(self):
        return self.traj is not None


def guarded_run(mod, method, q0, v0, h, t_end, p, save_every=1, repeats=1, **kwargs):
    """simulate(...) repeated ``repeats`` times, keeping the fastest wall_time; a SimulationError
    (blow-up, Newton divergence, singular mass, refused input) becomes a failed Run."""
    from ..simulation import simulate
    best, traj = np.inf, None
    for _ in range(max(1, repeats)):
        start = time.perf_counter()
        try:
            with warnings.catch_warnings():
                # Sweeps run past the stable range on purpose and measure the error themselves.
                warnings.simplefilter("ignore", EnergyWarning)
                traj = simulate(mod, method, q0, v0, t_end=t_end, h=h, params=p,
                                save_every=save_every, **kwargs)
        except SimulationError as exc:
            # The time to failure includes the glue's warm-up call (a cache load once the
            # method has run before): an upper bound, only used to place the failure marker.
            when = getattr(exc, "time", None)
            return Run(None, time.perf_counter() - start, str(exc).splitlines()[0],
                       float("nan") if when is None else float(when))
        best = min(best, traj.wall_time)
    return Run(traj, best)


def short_error(message):
    """'step 57 of 1000 (t = 0.57, h = 0.01)' out of a SimulationError's first line (whose form
    is '<model>, <method>: step ... (t = ..., h = ...): what happened'), else its first 60
    characters."""
    head, sep, rest = message.partition(": step ")
    if sep:
        return "failed at step " + rest.split(")")[0] + ")"
    return "failed: " + message[:60]


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


def md_table(headers, rows):
    """Markdown table lines from a header list and rows of already formatted cells."""
    lines = ["| " + " | ".join(headers) + " |", "|" + "---|" * len(headers)]
    lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return lines


def fmt(x, spec=".2e"):
    """A number for a table; '-' for None/NaN, 'inf' kept."""
    if x is None or (isinstance(x, float) and np.isnan(x)):
        return "-"
    return format(x, spec)


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
