"""`lagrange-gen bench stepapi`: the cost of a control loop written in Python.

On the cart pole (models/cart_pole.py, the cart pendulum with a force input) with midpoint,
h = 1e-3, all in one process:

* Stepper.step(u): microseconds per call (one step each), with the same u every call and with
  a u that changes every call (the method's prepare runs again: midpoint recomputes p = H v),
  and the same steps taken k at a time inside compiled code (step(u, k)): the difference is
  the overhead of one call;
* simulate(..., t_end = t0 + h) once per control step, the way before the step API;
* a jitted controller inside simulate's loop (control=) against a constant input: the hook's
  cost per step.

Each figure is the best of ``repeats`` timings (the machine is shared: the minimum is the one
least disturbed). Writes reports/stepapi.md.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np


def _best(fn, setup, repeats):
    """Shortest of ``repeats`` timings of fn(setup()), setup outside the clock."""
    times = []
    for _ in range(repeats):
        arg = setup()
        start = time.perf_counter()
        fn(arg)
        times.append(time.perf_counter() - start)
    return min(times)


def measure(model_file, gen_dir, quick=False, repeats=5):
    """{name: microseconds} of the step API and its alternatives (see the module docstring)."""
    import numba

    import lagrange_gen as lg
    module = lg.load(model_file, out_dir=gen_dir)
    h, calls = 1e-3, 2_000 if quick else 20_000
    q0 = [0.0, np.pi - 0.3]      # swinging below the cart: the same work per step throughout

    def fresh():
        stepper = lg.Stepper(module, "midpoint", h=h, q0=q0)
        stepper.step(0.0)
        return stepper

    def python_loop(stepper):
        for _ in range(calls):
            stepper.step(0.0)

    per_call = _best(python_loop, fresh, repeats) / calls * 1e6
    inputs = [1e-3 * (i % 2) for i in range(calls)]

    def changing_loop(stepper):
        for u in inputs:
            stepper.step(u)

    per_call_changing = _best(changing_loop, fresh, repeats) / calls * 1e6
    inside = _best(lambda stepper: stepper.step(0.0, k=calls), fresh, repeats) / calls * 1e6
    sims = max(calls // 100, 20)
    lg.simulate(module, "midpoint", q0=q0, t_end=h, h=h, params={"u": 0.0})

    def simulate_loop(_):
        q, v = np.array(q0), np.zeros(2)
        for i in range(sims):
            tr = lg.simulate(module, "midpoint", q0=q, v0=v, t0=i * h, t_end=(i + 1) * h, h=h,
                             params={"u": 0.0})
            q, v = tr.q[-1], tr.v[-1]

    per_simulate = _best(simulate_loop, lambda: None, repeats) / sims * 1e6

    @numba.njit
    def hold(t, q, qd, p):
        return 0.0

    steps = calls
    run = dict(q0=q0, t_end=steps * h, h=h, save_every=steps)
    lg.simulate(module, "midpoint", control=hold, **dict(run, t_end=h, save_every=1))
    hooked = min(lg.simulate(module, "midpoint", control=hold, **run).wall_time
                 for _ in range(repeats)) / steps * 1e6
    plain = min(lg.simulate(module, "midpoint", params={"u": 0.0}, **run).wall_time
                for _ in range(repeats)) / steps * 1e6
    return dict(per_call=per_call, per_call_changing=per_call_changing, inside=inside, overhead=per_call - inside,
                per_simulate=per_simulate, hooked=hooked, plain=plain, calls=calls)


def report(r) -> str:
    return "\n".join([
        "# Step API: a control loop in Python",
        "",
        "`lagrange-gen bench stepapi`: cart pole (models/cart_pole.py), midpoint, h = 1e-3, one "
        f"process, best of 5; {r['calls']} calls.",
        "",
        "| what | us |",
        "|---|---|",
        f"| Stepper.step(u), per call (one step), u the same every call | {r['per_call']:.2f} |",
        f"| Stepper.step(u), per call, u changing every call (prepare runs again) | "
        f"{r['per_call_changing']:.2f} |",
        f"| the same steps inside compiled code, step(u, k), per step | {r['inside']:.2f} |",
        f"| overhead of one step() call, same u (difference; goal <= 5) | {r['overhead']:.2f} |",
        f"| simulate() for one step, per call (before the step API) | {r['per_simulate']:.1f} |",
        f"| simulate with a jitted controller in the loop, per step | {r['hooked']:.3f} |",
        f"| simulate with a constant input, per step | {r['plain']:.3f} |",
        "",
    ])


def run_stepapi_bench(out_path, models_dir="models", quick=False):
    """Measure and write the report; returns its text."""
    import tempfile
    with tempfile.TemporaryDirectory() as gen_dir:
        r = measure(Path(models_dir) / "cart_pole.py", gen_dir, quick=quick)
    text = report(r)
    Path(out_path).parent.mkdir(parents=True, exist_ok=True)
    Path(out_path).write_text(text)
    print(text)
    return text
