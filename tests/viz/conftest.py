"""Runs shared by the visualization tests, each simulated once per session (short, coarse)."""

from pathlib import Path

import numpy as np
import pytest

from lagrange_gen.codegen import generate_model
from lagrange_gen.run.loader import import_generated
from lagrange_gen.run.simulate import simulate

EVENTS_MODEL = Path(__file__).resolve().parent.parent / "events" / "models" / "cart_pendulum_events.py"


@pytest.fixture(scope="session")
def run(generated, gen_dir):
    """Return a function: kind -> Trajectory of one short run of that kind (simulated once):
    pendulum (double pendulum, rk4), constrained (Cartesian pendulum, rattle), nonsmooth
    (Prandtl, implicit_euler), events (cart pendulum with events, dop853)."""
    cache = {}

    def get(kind):
        if kind not in cache:
            cache[kind] = _simulate(kind, generated, gen_dir)
        return cache[kind]
    return get


def _simulate(kind, generated, gen_dir):
    if kind == "pendulum":
        return simulate(generated("double_pendulum"), "rk4", [2.0, 2.5], [0.0, 0.0],
                        t_end=2.0, h=1e-3, save_every=20)
    if kind == "constrained":
        return simulate(generated("cartesian_pendulum"), "rattle", [0.6, -0.8], [0.8, 0.6],
                        t_end=1.0, h=1e-3, save_every=10)
    if kind == "nonsmooth":
        return simulate(generated("prandtl"), "implicit_euler", [0.0], [0.5], t_end=20.0,
                        h=1e-2, save_every=10)
    if kind == "events":
        module = import_generated(generate_model(EVENTS_MODEL, gen_dir).path)
        return simulate(module, "dop853", [0.1, 0.5], t_end=3.0, rtol=1e-8, atol=1e-8,
                        t_eval=np.linspace(0, 3, 31))
    raise ValueError(kind)
