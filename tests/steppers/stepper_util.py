"""Helpers of the stepper tests: generated test models, runs through the glue (conftest.glue).

There is deliberately no conftest.py in this directory: test modules of other directories import
names from the top-level conftest, and a second conftest module would shadow it. Test modules
import the ``model`` fixture from here instead.
"""

import atexit
import shutil
import tempfile
from pathlib import Path

import numpy as np
import pytest

from lg_test_support import glue
from lagrange_gen.codegen import generate_model
from lagrange_gen.run.loader import import_generated

from lagrange_gen.steppers.core import registry
from lagrange_gen.steppers.core.layout import N_STATS
from lagrange_gen.steppers.core.method_spec import make_settings
from lagrange_gen.steppers.core.status import OK

HERE = Path(__file__).resolve().parent
MODEL_FILES = {
    "oscillator": HERE / "models" / "oscillator.py",
    "pendulum": HERE / "models" / "pendulum.py",
    "double_pendulum": HERE / "models" / "double_pendulum.py",
    "driven_oscillator": HERE / "models" / "driven_oscillator.py",
    "spherical": HERE / "models" / "spherical.py",
    "cart_pendulum": HERE.parent.parent / "models" / "cart_pendulum.py",
}

_GEN_DIR = []
_MODULES = {}


def generated_model(name):
    """Model name (see MODEL_FILES) -> imported generated module, generated once per process
    into a temporary directory. Modules carry the glue of every method; numba compiles a
    run_<method> on its first call only."""
    if name not in _MODULES:
        if not _GEN_DIR:
            _GEN_DIR.append(Path(tempfile.mkdtemp(prefix="lagrange_gen_stepper_models_")))
            atexit.register(shutil.rmtree, _GEN_DIR[0], True)
        _MODULES[name] = import_generated(generate_model(MODEL_FILES[name], _GEN_DIR[0]).path)
    return _MODULES[name]


@pytest.fixture(scope="session")
def model():
    """The generated_model function (a fixture, so tests read ``model("pendulum")``)."""
    return generated_model


def params(mod, **given):
    """Parameter vector in PARAMS order: defaults overridden by ``given``."""
    values = dict(zip(mod.PARAMS, mod.DEFAULTS))
    values.update(given)
    return np.array([values[name] for name in mod.PARAMS], dtype=np.float64)


def run(mod, method, q0, v0, h, n_steps, p, t0=0.0, save_every=1, settings=None):
    """Integrate with run_<method> (an unconstrained method without saved fields); returns
    (t (S,), q (S, n), v (S, n), stats (S, N_STATS)). settings: a dict of the method's
    settings (spec.make_settings), default its defaults."""
    n = mod.N_COORDS
    rows = n_steps // save_every + 1
    out_t, out_q, out_v = np.empty(rows), np.empty((rows, n)), np.empty((rows, n))
    out_stats, out_extra, last = np.empty((rows, N_STATS)), np.empty((rows, 0)), np.empty(2 * n + 3)
    record = make_settings(registry.spec(method), settings or {})
    status, done, _ = glue(mod, method)(
        np.asarray(q0, dtype=np.float64), np.asarray(v0, dtype=np.float64), float(t0), float(h),
        n_steps, save_every, p, record, out_t, out_q, out_v, out_stats, out_extra, last,
        np.empty((0, 3 + 2 * n)))
    assert status == OK, f"{method}: status {status} at step {done}"
    return out_t, out_q, out_v, out_stats


def one_step(mod, method, q, v, h, p, t0=0.0, settings=None):
    """(q+, v+) after one step of size h (h may be negative)."""
    _, qs, vs, _ = run(mod, method, q, v, h, 1, p, t0=t0, settings=settings)
    return qs[1].copy(), vs[1].copy()


def mass_matrix(mod, q, p):
    H = np.empty((mod.N_COORDS, mod.N_COORDS))
    mod.mass_matrix(np.asarray(q, dtype=np.float64), 0.0, p, H)
    return H


def reference_solution(mod, q0, v0, t_end, p, rtol=1e-13, atol=1e-13):
    """(q, v) at t_end from scipy's DOP853 on the generated forward_dynamics."""
    from scipy.integrate import solve_ivp
    n = mod.N_COORDS
    H, qdd = np.empty((n, n)), np.empty(n)

    def rhs(t, y):
        assert mod.forward_dynamics(y[:n], y[n:], t, p, H, qdd) == OK
        return np.concatenate([y[n:], qdd])

    sol = solve_ivp(rhs, (0.0, t_end), np.concatenate([q0, v0]), method="DOP853",
                    rtol=rtol, atol=atol)
    assert sol.success
    return sol.y[:n, -1], sol.y[n:, -1]
