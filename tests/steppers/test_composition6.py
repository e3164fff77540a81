"""The sixth-order composition of verlet (steppers/methods/composition6.py) over long runs: its energy
error stays bounded (no drift) and is of its order's size; a failing substep of a composition
restores the state the step started from. Its fitted order is in
test_stepper_convergence.py, symmetry and symplecticity in test_stepper_geometry.py, its
stability limit in test_stepper_stability.py."""

import atexit
import shutil
import tempfile
from pathlib import Path

import numpy as np
import pytest

from lagrange_gen.codegen import generate_model
from lagrange_gen.run.loader import import_generated
from lagrange_gen.steppers.core import registry
from lagrange_gen.steppers.core.layout import N_STATS
from lagrange_gen.steppers.core.method_spec import make_settings
from lagrange_gen.steppers.core.status import OK
from lg_test_support import glue
from stepper_util import HERE, model, params, run  # model is a fixture

# (model, q0, v0, h, steps, bound on the energy error over the first fifth): the double
# pendulum runs verlet's Newton path (H depends on q), the pendulum its explicit path; both
# nonlinear. Bounds: measured values (5.5e-7, 1.6e-7) times about 5, far below the triple
# jump's at the same h (8e-4, 2e-4).
CASES = [("double_pendulum", [0.7, -0.4], [0.9, 1.3], 0.02, 50_000, 3e-6),
         ("pendulum", [2.5], [0.0], 0.2, 50_000, 8e-7)]


def energy_error_fifths(mod, method, q0, v0, h, n_steps):
    """(max |E - E0| over the first fifth, over the last fifth) of the run."""
    _, _, _, stats = run(mod, method, np.array(q0), np.array(v0), h, n_steps, params(mod),
                         save_every=50)
    dE = np.abs(stats[:, 0] - stats[0, 0])
    k = len(dE) // 5
    return dE[1:k].max(), dE[-k:].max()


@pytest.mark.parametrize("name, q0, v0, h, n_steps, bound", CASES)
def test_energy_error_is_small_and_does_not_drift(model, name, q0, v0, h, n_steps, bound):
    mod = model(name)
    first, last = energy_error_fifths(mod, "composition6", q0, v0, h, n_steps)
    assert 0 < first < bound, first
    assert last <= 2 * first, (first, last)


def test_energy_error_falls_as_h_to_the_sixth(model):
    """Halving h divides the (bounded) energy error by about 2^6 = 64 on the pendulum."""
    mod = model("pendulum")
    coarse, _ = energy_error_fifths(mod, "composition6", [2.5], [0.0], 0.2, 5_000)
    fine, _ = energy_error_fifths(mod, "composition6", [2.5], [0.0], 0.1, 10_000)
    assert 40 < coarse / fine < 100, (coarse, fine)


@pytest.mark.parametrize("method", ["composition", "composition6"])
def test_a_failing_substep_leaves_the_state_at_the_start_of_the_step(method):
    """V = c sqrt(x) on verlet's Newton path: from x = 0.8 h moving left at unit speed, a later
    substep of the composition (composition6: its fifth, at 0.90 h) drives x below 0, where
    sqrt(x) is NaN. The run reports the failure with the state the step started from (the last
    saved row), not the one the earlier substeps reached."""
    mod = generated_model_for(method)
    h = 0.01
    n = 1
    rows = 3
    out = (np.empty(rows), np.empty((rows, n)), np.empty((rows, n)), np.empty((rows, N_STATS)),
           np.empty((rows, 0)), np.empty(2 * n + 3), np.empty((0, 3 + 2 * n)))
    settings = make_settings(registry.spec(method), {"newton_always": True})
    status, done, _ = glue(mod, method)(
        np.array([0.8 * h]), np.array([-1.0]), 0.0, h, 2, 1, np.array([1.0, 1e-6]), settings,
        *out)
    assert status != OK and done == 0, (status, done)
    last = out[5]
    assert last[0] == 0.0
    assert last[1] == 0.8 * h and last[2] == -1.0, last


_FAILING = {}


def generated_model_for(method):
    """The sqrt potential, generated once with the compositions' glue only."""
    if not _FAILING:
        out = Path(tempfile.mkdtemp(prefix="lagrange_gen_composition_"))
        atexit.register(shutil.rmtree, out, True)
        _FAILING["mod"] = import_generated(generate_model(
            HERE / "models" / "sqrt_potential.py", out,
            methods=["composition", "composition6"]).path)
    return _FAILING["mod"]
