"""The sixth-order composition of verlet (steppers/composition6.py) over long runs: its energy
error stays bounded (no drift) and is of its order's size. Its fitted order is in
test_stepper_convergence.py, symmetry and symplecticity in test_stepper_geometry.py, its
stability limit in test_stepper_stability.py."""

import numpy as np
import pytest

from stepper_util import model, params, run  # model is a fixture

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
