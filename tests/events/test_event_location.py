"""Events located by the fixed-step loop (base.run_loop, events.py, hermite.py), called through
the generated glue: crossing times against closed forms at the order of the method, directions,
terminal stop, a full out_events buffer, backward integration, the table for Trajectory.

Oscillator (tests/events/models/oscillator_events.py): x'' = -omega^2 x, omega = 2, from
(x, v) = (1, 0): x = cos 2t. Falling mass: y = y0 - g t^2 / 2.
"""

import math

import numpy as np
import pytest

from events_util import Run, generated
from lagrange_gen.steppers.core.events import events_table
from lagrange_gen.steppers.core.status import OK

OMEGA = 2.0
T_END = 3.0
A_LEVEL, T_MARK = 0.5, 1.234          # the oscillator's defaults of a and t_mark


def oscillator_events():
    """[(t, name, direction)] of x = cos 2t on (0, T_END], in time order (closed form)."""
    expected = [(math.pi / 4, "zero", -1), (math.pi / 4, "down", -1),
                (3 * math.pi / 4, "zero", 1), (3 * math.pi / 4, "up", 1),
                (math.pi / 2, "turn", 1),                  # x' = -2 sin 2t rises through 0
                (math.acos(A_LEVEL) / OMEGA, "level", -1),
                (math.pi - math.acos(A_LEVEL) / OMEGA, "level", 1),
                (T_MARK, "clock", 1)]
    return sorted(expected, key=lambda e: e[0])


def run_oscillator(method, h, t_end=T_END, **kwargs):
    return Run(generated("oscillator_events"), method, [1.0], [0.0], h, round(t_end / h), **kwargs)


@pytest.mark.parametrize("method, tol", [("midpoint", 2e-4), ("rk4", 1e-8)])
def test_every_crossing_is_found_with_its_name_direction_and_time(method, tol):
    run = run_oscillator(method, 0.01)
    assert (run.status, run.steps) == (OK, 300)
    expected = oscillator_events()
    assert run.n_events == len(expected)
    rows = run.rows()
    # Events of one time (zero and down) come in index order; compare as sets per time.
    got = sorted((round(t, 2), run.names[int(k)], int(d)) for t, k, d in rows[:, :3])
    assert got == sorted((round(t, 2), name, d) for t, name, d in expected)
    assert np.all(np.diff(rows[:, 0]) >= 0), "rows are not in time order"
    for t, name, _ in expected:
        assert abs(run.times(name) - t).min() <= tol, (name, run.times(name), t)


def test_recorded_state_is_the_state_at_the_event():
    run = run_oscillator("rk4", 0.01)
    for t, _, _, x, v in run.rows("zero"):
        assert abs(x) <= 1e-12                        # g = x vanishes there
        assert v == pytest.approx(-OMEGA * math.sin(OMEGA * t), abs=1e-8)
    for t, _, _, x, v in run.rows("level"):
        assert x == pytest.approx(A_LEVEL, abs=1e-12)


@pytest.mark.parametrize("method", ["midpoint", "rk4"])
def test_a_time_event_is_exact(method):
    """g = t - t_mark is linear in t: the refinement lands on t_mark to rounding."""
    assert run_oscillator(method, 0.01).times("clock") == pytest.approx([T_MARK], abs=1e-13)


def event_time_error(method, h):
    """Largest error of the state events' times against the closed form."""
    run = run_oscillator(method, h)
    return max(abs(run.times(name) - t).min()
               for t, name, _ in oscillator_events() if name != "clock")


@pytest.mark.parametrize("method, order", [("midpoint", 2), ("rk4", 4)])
def test_event_times_converge_at_the_order_of_the_method(method, order):
    """Halving h divides the event time error by 2^order: the interpolant of the step does
    not limit the accuracy (for rk4 it would show as a ratio below 16)."""
    steps = [0.04, 0.02, 0.01]
    errors = [event_time_error(method, h) for h in steps]
    rates = [math.log2(a / b) for a, b in zip(errors, errors[1:])]
    assert all(abs(r - order) < 0.25 for r in rates), (errors, rates)


def test_direction_filters_keep_only_their_crossings():
    run = run_oscillator("rk4", 0.01, t_end=10.0)
    zero = run.rows("zero")
    assert len(zero) == 6 and set(zero[:, 2]) == {-1.0, 1.0}
    for name, sense in (("up", 1.0), ("down", -1.0)):
        rows = run.rows(name)
        assert np.all(rows[:, 2] == sense)
        np.testing.assert_array_equal(rows[:, 0], zero[zero[:, 2] == sense][:, 0])


def test_backward_integration_records_the_direction_in_the_order_of_integration():
    """From t = 0 to -1 (h < 0) x = cos 2t falls through a = 0.5 at -pi/6 and through 0 at
    -pi/4 in the order of integration."""
    run = run_oscillator("rk4", -0.01, t_end=-1.0)
    assert (run.status, run.steps) == (OK, 100)
    assert [run.names[int(k)] for k in run.rows()[:, 1]] == ["level", "zero", "down"]
    assert np.all(run.rows()[:, 2] == -1.0)
    np.testing.assert_allclose(run.rows()[:, 0], [-math.pi / 6, -math.pi / 4, -math.pi / 4],
                               atol=1e-8)


def test_full_buffer_keeps_counting_without_writing():
    full = run_oscillator("rk4", 0.01, max_events=50)
    small = run_oscillator("rk4", 0.01, max_events=2)
    none = run_oscillator("rk4", 0.01, max_events=0)
    assert full.n_events == small.n_events == none.n_events == 8
    np.testing.assert_array_equal(small.events, full.events[:2])
    np.testing.assert_array_equal(small.last, full.last)       # the run itself is unchanged
    with pytest.warns(RuntimeWarning, match="8 events were located, only the first 2"):
        table = events_table(generated("oscillator_events"), small.events, small.n_events)
    assert len(table) == 2


@pytest.mark.parametrize("method", ["midpoint", "rk4"])
def test_terminal_event_stops_the_run_at_the_event(method):
    """A mass falls from y0 = 2: it passes y = 1 (recorded, not terminal) at sqrt(2 / g), hits
    the ground (terminal) at sqrt(2 y0 / g) with speed -sqrt(2 g y0). Both methods are exact on
    a constant force and the interpolant is exact on a quadratic, so the times are exact to
    rounding; the run ends there with status OK."""
    mod = generated("falling_mass")
    g, y0, h = 9.81, 2.0, 0.01
    run = Run(mod, method, [y0], [0.0], h, 100)
    t_hit = math.sqrt(2 * y0 / g)
    assert run.status == OK
    assert run.steps == math.floor(t_hit / h)                  # the step it happened in
    assert run.n_events == 2
    np.testing.assert_allclose(run.rows()[:, 0], [math.sqrt(2 / g), t_hit], rtol=1e-12)
    assert [run.names[int(k)] for k in run.rows()[:, 1]] == ["half_way", "ground"]
    assert np.all(run.rows()[:, 2] == -1.0)
    t, y, v = run.last[:3]
    assert t == pytest.approx(t_hit, rel=1e-12)
    assert abs(y) <= 1e-12 and v == pytest.approx(-math.sqrt(2 * g * y0), rel=1e-12)
    saved = run.steps + 1                                      # rows 0 .. steps
    assert not np.isnan(run.t[:saved]).any() and np.isnan(run.t[saved:]).all()
    assert run.t[saved - 1] < t_hit


def test_events_table_names_the_events():
    mod = generated("falling_mass")
    run = Run(mod, "midpoint", [2.0], [0.0], 0.01, 100)
    table = events_table(mod, run.events, run.n_events)
    assert table.dtype.names == ("t", "name", "direction", "q", "v")
    assert list(table["name"]) == ["half_way", "ground"]
    assert list(table["direction"]) == [-1, -1]
    assert table["q"].shape == (2, 1)
    np.testing.assert_array_equal(table["v"][:, 0], run.rows()[:, 4])


def test_on_a_constrained_model_the_crossing_converges_at_the_order_of_the_method():
    """rattle (order 2) on the Cartesian pendulum released from rest at theta0 = 0.8: the bob
    passes the vertical after K(sin^2(theta0 / 2)) / omega (scipy's ellipk takes m = k^2). The
    interpolant is the cubic one there (multiplier forces: no accelerations from H^-1 rhs)."""
    from scipy.special import ellipk
    mod = generated("cartesian_pendulum_events", ["rattle"])
    theta0, omega = 0.8, math.sqrt(9.81)
    t_quarter = ellipk(math.sin(theta0 / 2) ** 2) / omega
    q0 = [-math.sin(theta0), -math.cos(theta0)]
    errors = []
    for h in (0.02, 0.01, 0.005):
        run = Run(mod, "rattle", q0, [0.0, 0.0], h, round(1.0 / h))
        assert run.status == OK and run.n_events == 1
        t, _, sense, x, y = run.rows()[0, :5]
        assert sense == 1.0 and abs(x) <= 1e-12 and y == pytest.approx(-1.0, abs=1e-3)
        errors.append(abs(t - t_quarter))
    rates = [math.log2(a / b) for a, b in zip(errors, errors[1:])]
    assert errors[-1] < 1e-3 and all(abs(r - 2) < 0.25 for r in rates), (errors, rates)
