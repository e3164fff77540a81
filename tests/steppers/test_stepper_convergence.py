"""Fitted convergence order against scipy's DOP853 (rtol = atol = 1e-13) on the generated
forward_dynamics. The driven oscillator checks that damping and time-dependent forces enter
every scheme correctly (through momentum_rate or rhs)."""

import numpy as np
import pytest

from stepper_util import model, params, reference_solution, run  # model is a fixture
from lagrange_gen.steppers.core.registry import CONSTRAINED_METHODS, INFO, METHODS

T_END = 1.0
# Step counts per order: small enough steps to be in the asymptotic regime, errors still far
# above the reference's accuracy (about 1e-12).
STEPS = {1: (128, 256, 512, 1024, 2048), 2: (32, 64, 128, 256, 512), 4: (32, 64, 128, 256, 512),
         6: (8, 12, 16, 24, 32)}
CASES = {
    "cart_pendulum": ([0.3, 0.8], [0.2, -0.5]),
    "double_pendulum": ([0.3, 0.8], [0.2, -0.5]),
    "driven_oscillator": ([0.3], [0.2]),
}


@pytest.fixture(scope="module")
def reference(model):
    cache = {}

    def get(name):
        if name not in cache:
            mod = model(name)
            q0, v0 = (np.array(x, dtype=float) for x in CASES[name])
            cache[name] = reference_solution(mod, q0, v0, T_END, params(mod))
        return cache[name]
    return get


def fitted_order(mod, method, q0, v0, q_ref, v_ref):
    order = INFO[method].order
    hs, errors = [], []
    for n in STEPS[order]:
        h = T_END / n
        _, qs, vs, _ = run(mod, method, q0, v0, h, n, params(mod), save_every=n)
        hs.append(h)
        errors.append(max(np.abs(qs[-1] - q_ref).max(), np.abs(vs[-1] - v_ref).max()))
    return np.polyfit(np.log(hs), np.log(errors), 1)[0], errors


@pytest.mark.parametrize("name", sorted(CASES))
# The constrained methods need a model with constraints (tests/constraints/ fits their order).
# dop853 chooses its own steps: tests/steppers/test_dop853.py checks its orders.
@pytest.mark.parametrize("method", [m for m in METHODS if m not in CONSTRAINED_METHODS
                                    and not INFO[m].adaptive and not INFO[m].contacts
                                    and not INFO[m].nonholonomic])
def test_fitted_order(model, reference, name, method):
    mod = model(name)
    q0, v0 = (np.array(x, dtype=float) for x in CASES[name])
    q_ref, v_ref = reference(name)
    slope, errors = fitted_order(mod, method, q0, v0, q_ref, v_ref)
    assert abs(slope - INFO[method].order) <= 0.15, (slope, errors)
