"""Running a model the way a user does, for verification: its generated module, a parameter
vector, which methods apply, and one guarded run through the public ``simulate`` driver.

A run's exceptions are what a failed run looks like to a user: a SimulationError (blow-up,
Newton divergence, singular mass, refused input) becomes a failed :class:`Run`, not a crash.
"""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import EnergyWarning, SimulationError
from ..steppers.core import registry

NOT_AVAILABLE = "not available in this build"


def constrained_methods():
    """Constrained methods registered in this build, in registry order (maybe empty)."""
    return registry.CONSTRAINED_METHODS


def unconstrained_methods():
    """Fixed-step methods for unconstrained smooth models: not the constrained, the nonsmooth,
    the contact, the nonholonomic or the adaptive ones (the hard cases compare methods at a
    given step h)."""
    return tuple(m for m in registry.METHODS if not (
        registry.spec(m).constraints or registry.spec(m).elements or registry.spec(m).adaptive
        or registry.spec(m).contacts or registry.spec(m).nonholonomic))


def smooth_adaptive_methods():
    """Adaptive methods for unconstrained smooth models (dop853; not the contact one)."""
    return tuple(m for m in registry.ADAPTIVE_METHODS if not registry.spec(m).contacts)


def methods_for(mod, methods=None):
    """Methods that apply to a module (constrained ones on constrained models, else the rest),
    restricted to ``methods`` when given."""
    pool = constrained_methods() if mod.N_CONSTRAINTS else unconstrained_methods()
    return [m for m in pool if methods is None or m in methods]


def has_method(name):
    return name in registry.METHODS


def load_module(models_dir, stem, gen_dir, **options):
    """Generated module of models_dir/<stem>.py (generated into gen_dir when missing or stale)."""
    from ..run.loader import load
    return load(Path(models_dir) / f"{stem}.py", out_dir=gen_dir, options=options or None)


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
    time to failure of a failed run (the timing suites read it, verdicts never do)."""

    traj: object
    wall: float
    error: str = ""
    fail_time: float = float("nan")     # simulated time of the failure (SimulationError.time)

    @property
    def ok(self):
        return self.traj is not None


def guarded_run(mod, method, q0, v0, h, t_end, p, save_every=1, repeats=1, **kwargs):
    """simulate(...) repeated ``repeats`` times, keeping the fastest wall_time; a SimulationError
    becomes a failed Run."""
    from ..run.simulate import simulate
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


def fmt(x, spec=".2e"):
    """A number for a verdict table; '-' for None/NaN, 'inf' kept."""
    if x is None or (isinstance(x, float) and np.isnan(x)):
        return "-"
    return format(x, spec)


def md_table(headers, rows):
    """Markdown table lines from a header list and rows of already formatted cells."""
    lines = ["| " + " | ".join(headers) + " |", "|" + "---|" * len(headers)]
    lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return lines
