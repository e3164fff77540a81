"""The run_<method> glue is cached on disk: a second process loads it instead of recompiling
(DESIGN.md section 5; the reason the glue exists, see steppers/core/registry.py)."""

import json
import subprocess
import sys

from lagrange_gen.codegen import generate_model

from stepper_util import MODEL_FILES

#: Explicit ones and each Newton path (the shared steppers/core/newton.py): a glue that numba cannot
#: cache ("dynamic globals") would recompile in every process.
METHODS = ("rk4", "verlet", "midpoint", "implicit_euler", "symplectic_euler")

SCRIPT = """
import json, sys
import numpy as np
from lagrange_gen.run.loader import import_generated
from lagrange_gen.steppers.core import registry
from lagrange_gen.steppers.core.layout import N_STATS
from lagrange_gen.steppers.core.method_spec import make_settings
mod = import_generated(sys.argv[1])
out = dict()
for method in sys.argv[2].split(","):
    run = getattr(mod, "run_" + method)
    rows = 11
    status, done, _ = run(np.array([0.1, 0.5]), np.zeros(2), 0.0, 1e-3, 10, 1,
                          mod.DEFAULT_PARAMS, make_settings(registry.spec(method), {}),
                          np.empty(rows), np.empty((rows, 2)), np.empty((rows, 2)),
                          np.empty((rows, N_STATS)), np.empty((rows, 0)), np.empty(7),
                          np.empty((0, 7)))
    out[method] = dict(status=int(status), hits=sum(run.stats.cache_hits.values()),
                       misses=sum(run.stats.cache_misses.values()))
print(json.dumps(out))
"""


def run_in_new_process(path):
    proc = subprocess.run([sys.executable, "-c", SCRIPT, str(path), ",".join(METHODS)],
                          capture_output=True,
                          text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout.strip().splitlines()[-1])


def test_second_process_loads_the_glue_from_numba_cache(tmp_path):
    path = generate_model(MODEL_FILES["cart_pendulum"], tmp_path).path
    first = run_in_new_process(path)
    second = run_in_new_process(path)
    for method in METHODS:
        assert first[method] == dict(status=0, hits=0, misses=1), first
        assert second[method] == dict(status=0, hits=1, misses=0), second
