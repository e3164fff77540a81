"""The step API compiles once per method for every model (steppers/core/step_api.py): its
state is a structref holding the model's kernel table, whose type numba keeps in its on-disk
cache, so a Stepper in a new process, on the model or on another one, compiles nothing."""

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

import lagrange_gen as lg

_CHILD = '''
import json, sys
import numpy as np
import lagrange_gen as lg
from lagrange_gen.jit.compile_notice import time_outermost_compiles
from lagrange_gen.run.loader import import_generated

compiles = time_outermost_compiles(lambda name: name)
out = {}
for path, q0, u in ((sys.argv[1], [0.0, 0.2], 0.5), (sys.argv[2], [0.3, -0.2], None)):
    stepper = lg.Stepper(import_generated(path), "midpoint", h=0.01, q0=q0)
    for _ in range(10):
        stepper.step(u)
    stepper.step(u, k=5)
    out[path] = stepper.state.tolist()
print(json.dumps(dict(compiled=sorted(compiles), states=out)))
'''


def _steps(module, q0, u):
    stepper = lg.Stepper(module, "midpoint", h=0.01, q0=q0)
    for _ in range(10):
        stepper.step(u)
    stepper.step(u, k=5)
    return stepper.state


def test_a_stepper_in_a_new_process_compiles_nothing(generated):
    """This process compiles (or loads) the step API of midpoint; a new process then runs a
    Stepper on the same model and on another (no inputs) without a compile, with the states of
    this process."""
    cart_pole, pendulum = generated("cart_pole"), generated("double_pendulum")
    here = {cart_pole.__file__: _steps(cart_pole, [0.0, 0.2], 0.5),
            pendulum.__file__: _steps(pendulum, [0.3, -0.2], None)}
    env = dict(os.environ)
    src = str(Path(lg.__file__).resolve().parents[1])
    env["PYTHONPATH"] = os.pathsep.join([src] + [p for p in env.get("PYTHONPATH", "").split(
        os.pathsep) if p])
    done = subprocess.run([sys.executable, "-c", _CHILD, cart_pole.__file__, pendulum.__file__],
                          env=env, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]
    child = json.loads(done.stdout.strip().splitlines()[-1])
    assert child["compiled"] == [], child["compiled"]
    for path, state in here.items():
        np.testing.assert_array_equal(np.array(child["states"][path]), state)


def test_the_step_api_equals_the_run_of_simulate(generated):
    """Fifteen midpoint steps through the Stepper equal simulate's, bit for bit, on a model
    without inputs (the state's kernel table is the portable glue's)."""
    pendulum = generated("double_pendulum")
    traj = lg.simulate(pendulum, "midpoint", q0=[0.3, -0.2], t_end=0.15, h=0.01, jit="portable")
    np.testing.assert_array_equal(_steps(pendulum, [0.3, -0.2], None),
                                  np.concatenate((traj.q[-1], traj.v[-1])))
