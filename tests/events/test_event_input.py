"""The model side of events: Model(events=...) in a model file, what bad input says (one
ModelError line naming the file and the event), what the generated module carries (the events
kernel and the EVENT_* constants, also for a model without events; frozen parameters in an
event), and the step interpolant (hermite.py) on polynomials it must reproduce exactly."""

import textwrap

import numpy as np
import pytest

from events_util import MODELS
from lagrange_gen import Event, ModelError, load_model
from lagrange_gen.codegen import generate_text
from lagrange_gen.run.loader import import_generated
from lagrange_gen.steppers.core import hermite

HEADER = textwrap.dedent("""\
    import sympy as sp
    from lagrange_gen import Event, Model, coordinates, parameters, t
    y = coordinates("y")
    g = parameters("g", defaults=(9.81,))
""")


def _error(tmp_path, events):
    path = tmp_path / "bad_events.py"
    path.write_text(HEADER + f"model = Model('bad', [y], T=y.d**2 / 2, V=g * y, events={events})\n")
    with pytest.raises(ModelError) as info:
        load_model(path)
    message = str(info.value)
    assert "\n" not in message and message.startswith(f"{path}: "), message
    return message


@pytest.mark.parametrize("events, says", [
    ("{'ground': sp.Matrix([y, y.d])}", "model bad: event ground is a 2 x 1 matrix, not a scalar"),
    ("{'ground': [y, y.d]}", "model bad: event ground is not a scalar SymPy expression"),
    ("{'ground': y - sp.Symbol('h0')}", "model bad: event ground uses symbol(s) h0 that are neither"),
    ("{'ground': Event(y, direction=2)}",
     "model bad: event ground: direction must be +1 (rising), -1 (falling) or 0 (both), got 2"),
    ("{'ground': Event(y, terminal='yes')}",
     "model bad: event ground: terminal must be True or False, got 'yes'"),
    ("{'ground': sp.Function('f')(y)}", "model bad: event ground contains an undefined function"),
    ("{'hit ground': y}", "event name 'hit ground' is not a valid Python identifier"),
    ("[y]", "model bad: events must be a dict {name: expression or Event"),
    # issue 34, item 8: accepted, never fired
    ("{'ground': y - y}", "model bad: event ground is the constant 0: it never crosses zero"),
    ("{'ground': sp.nan}", "model bad: event ground is the constant nan: it never crosses zero"),
    ("{'ground': Event(sp.Integer(3))}", "model bad: event ground is the constant 3"),
])
def test_bad_events_are_one_model_error_line_naming_file_and_event(tmp_path, events, says):
    assert says in _error(tmp_path, events)


def test_events_are_read_with_their_settings_and_parameters():
    model = load_model(MODELS / "oscillator_events.py")
    assert [e.name for e in model.events] == ["zero", "up", "down", "turn", "level", "clock"]
    assert [e.direction for e in model.events] == [0, 1, -1, 0, 0, 0]
    assert not any(e.terminal for e in model.events)
    # a and t_mark appear only in events: they are parameters of the model all the same
    assert [p.name for p in model.params] == ["m", "k", "a", "t_mark"]
    falling = load_model(MODELS / "falling_mass.py")
    assert [(e.name, e.terminal, e.direction) for e in falling.events] == [
        ("ground", True, -1), ("half_way", False, -1)]


def _module(tmp_path, path, **kwargs):
    model = load_model(path)
    text, _, target = generate_text(model, tmp_path, methods=["midpoint"], **kwargs)
    target.write_text(text)
    return text, import_generated(target)


def test_the_events_kernel_evaluates_every_event(tmp_path):
    _, mod = _module(tmp_path, MODELS / "oscillator_events.py")
    assert mod.N_EVENTS == 6 and mod.EVENT_NAMES[4] == "level"
    assert mod.EVENT_DIRECTION.tolist() == [0, 1, -1, 0, 0, 0]
    assert mod.EVENT_TERMINAL.tolist() == [False] * 6
    out = np.empty(6)
    p = np.array([1.0, 4.0, 0.3, 2.5])                          # m, k, a, t_mark
    mod.events(np.array([0.7]), np.array([-1.1]), 4.0, p, out)
    np.testing.assert_array_equal(out, [0.7, 0.7, 0.7, -1.1, 0.7 - 0.3, 4.0 - 2.5])


def test_frozen_parameters_are_folded_into_the_events(tmp_path):
    _, mod = _module(tmp_path, MODELS / "oscillator_events.py", freeze={"a": 0.25})
    assert "a" not in mod.PARAMS
    out = np.empty(6)
    mod.events(np.array([0.7]), np.array([0.0]), 0.0, np.array([1.0, 4.0, 1.234]), out)
    assert out[4] == pytest.approx(0.7 - 0.25)


def test_a_model_without_events_has_an_empty_kernel_and_no_events(tmp_path):
    path = tmp_path / "plain.py"
    path.write_text(HEADER + "model = Model('plain', [y], T=y.d**2 / 2, V=g * y)\n")
    text, mod = _module(tmp_path, path)
    assert "N_EVENTS = 0\nEVENT_NAMES = ()\n" in text
    assert mod.EVENT_TERMINAL.shape == (0,) and mod.EVENT_DIRECTION.dtype == np.int64
    assert mod.events(np.zeros(1), np.zeros(1), 0.0, mod.DEFAULT_PARAMS, np.empty(0)) is None


def _fitted(q0, v0, a0, q1, v1, a1, t0, h, quintic):
    ws = hermite.workspace(len(q0))
    ws.span[:] = (t0, h)
    for name, value in zip(("q0", "v0", "a0", "q1", "v1", "a1"), (q0, v0, a0, q1, v1, a1)):
        getattr(ws, name)[:] = value
    ws.quintic[0] = int(quintic)
    return ws


@pytest.mark.parametrize("quintic, degree", [(True, 5), (False, 3)])
def test_the_step_interpolant_reproduces_polynomials_of_its_degree(quintic, degree):
    """q(t) a polynomial of degree 5 (quintic, from q, v, a at both ends) or 3 (cubic, from q,
    v): the interpolant is q itself and its v is q' (also for a negative step)."""
    rng = np.random.default_rng(3)
    coef = rng.normal(size=(degree + 1, 2))                   # two coordinates
    poly = [np.polynomial.Polynomial(coef[:, i]) for i in range(2)]

    def state(t, k):
        return np.array([p.deriv(k)(t) for p in poly])

    for t0, h in ((0.3, 0.7), (1.1, -0.4)):
        t1 = t0 + h
        ws = _fitted(state(t0, 0), state(t0, 1), state(t0, 2), state(t1, 0), state(t1, 1),
                     state(t1, 2), t0, h, quintic)
        q, v = np.empty(2), np.empty(2)
        for s in (0.0, 0.2, 0.5, 0.93, 1.0):
            t = t0 + s * h
            hermite.interpolate(ws, t, q, v)
            np.testing.assert_allclose(q, state(t, 0), rtol=1e-12, atol=1e-12)
            np.testing.assert_allclose(v, state(t, 1), rtol=1e-11, atol=1e-11)


def test_the_cubic_interpolant_is_not_exact_on_a_quintic():
    """The test above can fail: the cubic interpolant misses a quintic."""
    def state(t, k):
        return np.array([[t**5, 5 * t**4, 20 * t**3][k]])
    ws = _fitted(state(0.0, 0), state(0.0, 1), state(0.0, 2), state(1.0, 0), state(1.0, 1),
                 state(1.0, 2), 0.0, 1.0, False)
    q, v = np.empty(1), np.empty(1)
    hermite.interpolate(ws, 0.5, q, v)
    assert abs(q[0] - 0.5**5) > 1e-3


def test_an_event_that_is_nan_at_the_initial_state_is_refused(tmp_path):
    """sqrt(y) at y0 < 0 is NaN: no crossing is ever seen (issue 34, item 8)."""
    import lagrange_gen as lg
    path = tmp_path / "nan_event.py"
    path.write_text(HEADER + "model = Model('nan_event', [y], T=y.d**2 / 2, V=g * y, "
                             "events={'root': sp.sqrt(y) - 1})\n")
    with pytest.raises(lg.SimulationError) as err:
        lg.simulate(path, "rk4", q0=[-1.0], t_end=0.1, h=0.01, out_dir=tmp_path / "gen")
    text = str(err.value)
    assert "\n" not in text and "event root" in text and "nan" in text, text
