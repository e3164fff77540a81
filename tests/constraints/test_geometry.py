"""Geometric properties of the constrained methods from the actual step map: symmetry (a step of
-h undoes a step of h) for rattle and the constrained midpoint, on the explicit path (Cartesian
pendulum) and the Newton path with H(q) (four-bar); implicit Euler is not symmetric."""

import numpy as np
import pytest

from constraint_util import four_bar_state, generated_model, params, pendulum_state
from lg_test_support import glue
from lagrange_gen.run.consistent import initial_multipliers
from lagrange_gen.steppers.core.layout import N_STATS
from lagrange_gen.steppers.core.method_spec import make_settings
from lagrange_gen.steppers.core.registry import spec


def one_step(mod, method, q, v, lam, h, p, t0=0.0):
    """(q+, v+, lam+) after one step of run_<method> (h may be negative)."""
    n, m = mod.N_COORDS, mod.N_CONSTRAINTS
    n_saved = spec(method).n_saved(n, m, mod.N_ELEMENTS)
    out_extra = np.zeros((2, n_saved))
    out_extra[0, :m] = lam
    out_q, out_v = np.empty((2, n)), np.empty((2, n))
    status, _, _ = glue(mod, method)(
        np.array(q, float), np.array(v, float), t0, h, 1, 1, p, make_settings(spec(method), {}),
        np.empty(2), out_q, out_v, np.empty((2, N_STATS)), out_extra,
        np.empty(2 * n + 3 + n_saved), np.empty((0, 3 + 2 * n)))
    assert status == 0
    return out_q[1], out_v[1], out_extra[1, :m]


CASES = {"cartesian_pendulum": lambda: pendulum_state(1.0, 2.0),
         "four_bar": lambda: four_bar_state(0.7, 3.0)}


@pytest.mark.parametrize("stem", sorted(CASES))
@pytest.mark.parametrize("method,symmetric", [("rattle", True), ("constrained_midpoint", True),
                                              ("constrained_implicit_euler", False)])
def test_symmetry(stem, method, symmetric):
    mod = generated_model(stem)
    p = params(mod)
    q0, v0 = CASES[stem]()
    lam0 = initial_multipliers(mod, q0, v0, 0.0, p)
    h = 0.05
    q1, v1, lam1 = one_step(mod, method, q0, v0, lam0, h, p)
    q2, v2, _ = one_step(mod, method, q1, v1, lam1, -h, p, t0=h)
    back = max(np.abs(q2 - q0).max(), np.abs(v2 - v0).max())
    if symmetric:
        assert back < 1e-11, back
    else:
        assert back > 1e-4, back
