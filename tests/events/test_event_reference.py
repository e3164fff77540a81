"""Event times of rk4 on a nonlinear two-degree-of-freedom model against scipy's DOP853 with
its own event location (solve_ivp events, on the same generated forward dynamics)."""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from events_util import Run, generated
from lagrange_gen.steppers.core.status import OK


def scipy_events(mod, q0, v0, t_end):
    """{event name: crossing times} from solve_ivp(DOP853, rtol = atol = 1e-12)."""
    n, p = mod.N_COORDS, mod.DEFAULT_PARAMS
    H, qdd = np.empty((n, n)), np.empty(n)

    def rhs(t, y):
        assert mod.forward_dynamics(y[:n], y[n:], t, p, H, qdd) == OK
        return np.concatenate([y[n:], qdd])

    def event(k):
        def g(t, y):
            out = np.empty(mod.N_EVENTS)
            mod.events(np.ascontiguousarray(y[:n]), np.ascontiguousarray(y[n:]), t, p, out)
            return out[k]
        g.direction = float(mod.EVENT_DIRECTION[k])
        return g

    sol = solve_ivp(rhs, (0.0, t_end), np.concatenate([q0, v0]), method="DOP853", rtol=1e-12,
                    atol=1e-12, events=[event(k) for k in range(mod.N_EVENTS)])
    assert sol.success
    return dict(zip(mod.EVENT_NAMES, sol.t_events))


def test_cart_pendulum_event_times_match_dop853():
    mod = generated("cart_pendulum_events", ["rk4"])
    q0, v0, h, t_end = np.array([0.1, 0.5]), np.zeros(2), 1e-3, 3.0
    run = Run(mod, "rk4", q0, v0, h, round(t_end / h))
    assert run.status == OK
    reference = scipy_events(mod, q0, v0, t_end)
    for name, times in reference.items():
        assert len(times) >= 2, name                        # the test sees several crossings
        np.testing.assert_allclose(run.times(name), times, rtol=0, atol=1e-10, err_msg=name)
    assert run.n_events == sum(len(t) for t in reference.values())
    assert np.all(run.rows("cart_stops")[:, 2] == -1.0)
