"""Helpers of the event tests: the test models generated once per process, a direct call of
the run_<method> glue that returns the located events.

No conftest.py here (see tests/steppers/stepper_util.py: it would shadow the top-level one).
"""

import atexit
import shutil
import tempfile
from pathlib import Path

import numpy as np

from lg_test_support import glue
from lagrange_gen.codegen import generate_model
from lagrange_gen.run.loader import import_generated
from lagrange_gen.steppers.core import registry
from lagrange_gen.steppers.core.layout import N_STATS
from lagrange_gen.steppers.core.method_spec import make_settings

MODELS = Path(__file__).resolve().parent / "models"
#: The methods the tests run (their glue only, to keep compile time down).
METHODS = ["midpoint", "rk4"]

_DIR = []
_MODULES = {}


def generated(stem, methods=None):
    """tests/events/models/<stem>.py -> its generated module with the glue of ``methods``
    (default METHODS), generated once per process into a temp dir."""
    if stem not in _MODULES:
        if not _DIR:
            _DIR.append(Path(tempfile.mkdtemp(prefix="lagrange_gen_event_models_")))
            atexit.register(shutil.rmtree, _DIR[0], True)
        path = generate_model(MODELS / f"{stem}.py", _DIR[0], methods=methods or METHODS).path
        _MODULES[stem] = import_generated(path)
    return _MODULES[stem]


class Run:
    """The outputs of one glue call: status, steps_done, n_events, t (S,), q, v (S, n),
    last (2n + 3 + n_saved,), events (E, 3 + 2n) as filled. The method's saved fields start
    at zero (constrained methods: multipliers, the first Newton guess)."""

    def __init__(self, mod, method, q0, v0, h, n_steps, t0=0.0, max_events=50, params=None):
        n = mod.N_COORDS
        rows = n_steps + 1
        self.t = np.full(rows, np.nan)
        self.q, self.v = np.full((rows, n), np.nan), np.full((rows, n), np.nan)
        spec = registry.spec(method)
        n_saved = spec.n_saved(n, mod.N_CONSTRAINTS, mod.N_ELEMENTS)
        self.last = np.full(2 * n + 3 + n_saved, np.nan)
        self.events = np.full((max_events, 3 + 2 * n), np.nan)
        p = mod.DEFAULT_PARAMS.copy() if params is None else np.asarray(params, dtype=np.float64)
        settings = make_settings(spec, {})
        self.status, self.steps, self.n_events = glue(mod, method)(
            np.asarray(q0, dtype=np.float64), np.asarray(v0, dtype=np.float64), float(t0),
            float(h), n_steps, 1, p, settings, self.t, self.q, self.v,
            np.empty((rows, N_STATS)), np.zeros((rows, n_saved)), self.last, self.events)
        self.names = mod.EVENT_NAMES

    def rows(self, name=None):
        """Recorded rows [t, k, direction, q, v] (of event ``name`` only, if given)."""
        rows = self.events[:min(self.n_events, self.events.shape[0])]
        if name is not None:
            rows = rows[rows[:, 1] == self.names.index(name)]
        return rows

    def times(self, name):
        return self.rows(name)[:, 0]
