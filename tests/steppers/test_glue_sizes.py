"""The glue refuses a state whose size is not the model's.

The steps loop to kern.N_COORDS (steppers/core/options.py, "Loop bounds") and the kernels index q and
qd by the model's coordinates, so a q0 or v0 of another length would be read past its end or
integrated with its extra entries silently ignored: run_loop and run_adaptive raise instead,
naming the sizes."""

import numpy as np
import pytest

from lg_test_support import glue
from lagrange_gen.steppers.core import registry
from lagrange_gen.steppers.core.layout import N_STATS
from lagrange_gen.steppers.core.method_spec import make_settings


def _fixed_step(mod, method, q0, v0, rows=3):
    n = mod.N_COORDS
    out = (np.empty(rows), np.empty((rows, n)), np.empty((rows, n)), np.empty((rows, N_STATS)),
           np.empty((rows, 0)), np.empty(2 * n + 3), np.empty((0, 3 + 2 * n)))
    record = make_settings(registry.spec(method), {})
    return glue(mod, method)(q0, v0, 0.0, 1e-3, rows - 1, 1, mod.DEFAULT_PARAMS.copy(), record,
                             *out)


def _adaptive(mod, q0, v0, rows=50):
    n = mod.N_COORDS
    out = (np.empty(rows), np.empty((rows, n)), np.empty((rows, n)), np.empty((rows, N_STATS)),
           np.empty((rows, 0)), np.empty(2 * n + 3), np.empty((0, 3 + 2 * n)))
    record = make_settings(registry.spec("dop853"), {})
    return glue(mod, "dop853")(q0, v0, 0.0, 0.01, mod.DEFAULT_PARAMS.copy(), record,
                               np.empty(0), *out, np.array([0.0, 0.0, 0.0, 0.0]))


@pytest.mark.parametrize("method", ["explicit_euler", "symplectic_euler"])
@pytest.mark.parametrize("sizes", [(3, 2), (2, 3), (1, 1)])
def test_fixed_step_glue_refuses_a_state_of_another_size(generated, method, sizes):
    mod = generated("cart_pendulum")                     # N_COORDS = 2
    q0, v0 = np.full(sizes[0], 0.1), np.zeros(sizes[1])
    with pytest.raises(ValueError, match="N_COORDS"):
        _fixed_step(mod, method, q0, v0)
    status, steps, _ = _fixed_step(mod, method, np.full(2, 0.1), np.zeros(2))
    assert (status, steps) == (0, 2)                     # the right size still runs


@pytest.mark.parametrize("sizes", [(3, 2), (2, 1)])
def test_adaptive_glue_refuses_a_state_of_another_size(generated, sizes):
    mod = generated("cart_pendulum")
    with pytest.raises(ValueError, match="N_COORDS"):
        _adaptive(mod, np.full(sizes[0], 0.1), np.zeros(sizes[1]))
    status, rows, _ = _adaptive(mod, np.full(2, 0.1), np.zeros(2))
    assert status == 0 and rows >= 2
