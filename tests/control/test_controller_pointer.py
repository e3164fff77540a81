"""Controllers and Signals through a function pointer (issue 40): the portable controlled glue
(run_<method>_controlled, jit/portable.py) is compiled once per method and cached by numba, and
reaches every input hook through one signature, so that a new controller in a new process
compiles no loop; its runs equal the specialized loop's bit for bit."""

import json
import os
import subprocess
import sys
from pathlib import Path

import numba
import numpy as np
import pytest

import lagrange_gen as lg
from lagrange_gen.jit import first_run, portable
from lagrange_gen.run import control
from lagrange_gen.run.control import Signal

Q0, H, T_END = [0.0, 0.2], 0.01, 0.5


@numba.njit
def _float(t, q, qd, p):
    return -2.0 * qd[1] + 0.1 * t


@numba.njit
def _array(t, q, qd, p, c):
    return np.array([-c[0] * q[1] - c[1] * qd[1]])


@numba.njit
def _tuple(t, q, qd, p):
    return (-3.0 * q[1] - 1.5 * qd[1],)


# name: (control, control_params); the same controllers are written again in the child
# process of test_a_new_controller_in_a_new_process_compiles_no_loop (new functions there)
CASES = {
    "float": (_float, None),
    "array": (_array, [5.0, 2.0]),
    "tuple": (_tuple, None),
    "zoh": (Signal([0.0, 0.1, 0.33], [1.0, -2.0, 0.5]), None),
    "linear": (Signal([0.0, 0.1, 0.33], [1.0, -2.0, 0.5], hold="linear"), None),
}


@pytest.fixture(scope="module")
def cart_pole(generated):
    return generated("cart_pole")


def _run(module, name, jit, control_fn=None):
    fn, c = CASES[name]
    return lg.simulate(module, "midpoint", q0=Q0, t_end=T_END, h=H, control=control_fn or fn,
                       control_params=c, jit=jit)


def _expected_inputs(name, traj):
    """The inputs held over the step starting at each saved row, from the controller's own
    Python (or the Signal's samples)."""
    fn, c = CASES[name]
    if isinstance(fn, Signal):
        times, values = fn.times, fn.values[:, 0]
        if fn.hold == "zoh":
            return values[np.searchsorted(times, traj.t + 1e-12, side="right") - 1]
        return np.interp(traj.t + H / 2, times, values)
    args = [(t, q, v, None) + (() if c is None else (np.array(c),))
            for t, q, v in zip(traj.t, traj.q, traj.v)]
    return np.array([float(np.atleast_1d(fn.py_func(*a))[0]) for a in args])


@pytest.mark.parametrize("name", CASES)
def test_the_controlled_glue_equals_the_specialized_loop_bit_for_bit(cart_pole, name):
    """Every kind of hook (a controller returning a float, an array with control_params, a
    tuple; a Signal held or interpolated) through the pointer gives the specialized loop's
    trajectory bit for bit, and the inputs are the controller's values at the saved states."""
    pointer = _run(cart_pole, name, "portable")
    inlined = _run(cart_pole, name, "specialized")
    assert (pointer.jit, inlined.jit) == ("portable", "specialized")
    for field in ("q", "v", "energy"):
        np.testing.assert_array_equal(getattr(pointer, field), getattr(inlined, field))
    for key in ("input_u", "output_tip_x"):
        np.testing.assert_array_equal(pointer.saved[key], inlined.saved[key])
    np.testing.assert_allclose(pointer.saved["input_u"][:, 0], _expected_inputs(name, pointer),
                               rtol=1e-13, atol=1e-13)
    assert np.ptp(pointer.saved["input_u"]) > 0.1          # the inputs do change


def test_the_controlled_glue_of_a_model_with_events_equals_the_specialized_loop(gen_dir):
    """run_<method>_controlled_events: the zero crossings of x located under a Signal and a
    controller equal the specialized loop's bit for bit."""
    from lagrange_gen.codegen import generate_model
    from lagrange_gen.run.loader import import_generated
    mod = import_generated(generate_model(Path(__file__).resolve().parent /
                                          "forced_oscillator_events.py", gen_dir).path)
    assert mod.N_EVENTS == 1 and mod.N_INPUTS == 1

    @numba.njit
    def push(t, q, qd, p):
        return 0.5 * np.sin(3.0 * t) - 0.2 * qd[0]

    for ctl in (push, Signal([0.0, 1.0, 2.5], [0.5, -1.0, 2.0])):
        runs = [lg.simulate(mod, "verlet", q0=[0.3], t_end=4.0, h=0.01, control=ctl, jit=jit)
                for jit in ("portable", "specialized")]
        assert [r.jit for r in runs] == ["portable", "specialized"]
        assert len(runs[0].events) >= 2
        for field in ("q", "v", "events"):
            np.testing.assert_array_equal(getattr(runs[0], field), getattr(runs[1], field))
        np.testing.assert_array_equal(runs[0].saved["input_u"], runs[1].saved["input_u"])


_CHILD = '''
import json, sys
import numba
import numpy as np
import lagrange_gen as lg
from lagrange_gen.jit import portable
from lagrange_gen.run import control
from lagrange_gen.run.control import Signal
from lagrange_gen.run.loader import import_generated

mod = import_generated(sys.argv[1])

@numba.njit
def float_again(t, q, qd, p):
    return -2.0 * qd[1] + 0.1 * t

@numba.njit
def array_again(t, q, qd, p, c):
    return np.array([-c[0] * q[1] - c[1] * qd[1]])

@numba.njit
def tuple_again(t, q, qd, p):
    return (-3.0 * q[1] - 1.5 * qd[1],)

cases = {"float": (float_again, None), "array": (array_again, [5.0, 2.0]),
         "tuple": (tuple_again, None),
         "zoh": (Signal([0.0, 0.1, 0.33], [1.0, -2.0, 0.5]), None),
         "linear": (Signal([0.0, 0.1, 0.33], [1.0, -2.0, 0.5], hold="linear"), None)}
ran, q = {}, {}
for name, (fn, c) in cases.items():
    traj = lg.simulate(mod, "midpoint", q0=[0.0, 0.2], t_end=0.5, h=0.01, control=fn,
                       control_params=c)
    ran[name] = traj.jit
    q[name] = traj.q.tolist()
glue = getattr(portable._glue_module("midpoint"), "run_midpoint_controlled")
print(json.dumps(dict(ran=ran, q=q, hits=sum(glue.stats.cache_hits.values()),
                      misses=sum(glue.stats.cache_misses.values()),
                      loops=sum(len(loop.overloads) for loop in control._RUNS.values()))))
'''


def test_a_new_controller_in_a_new_process_compiles_no_loop(cart_pole):
    """The portable controlled glue compiled here (for another controller) is loaded from
    numba's cache by a new process, which runs new controllers of the three kinds, with and
    without control_params, and Signals under jit="auto" without compiling a loop (no cache
    miss of the glue, its cache index untouched, no specialized loop compiled), with this
    process's results."""

    @numba.njit
    def warm(t, q, qd, p):
        return 0.0

    lg.simulate(cart_pole, "midpoint", q0=Q0, t_end=0.02, h=H, control=warm, jit="portable")
    glue = getattr(portable._glue_module("midpoint"), "run_midpoint_controlled")
    index = portable._index_state(glue._cache)
    assert index is not None and index[1] is not None, index      # on disk
    env = dict(os.environ)
    src = str(Path(lg.__file__).resolve().parents[1])
    env["PYTHONPATH"] = os.pathsep.join([src] + [p for p in env.get("PYTHONPATH", "").split(
        os.pathsep) if p])
    env[first_run.BACKGROUND_ENV] = "0"
    done = subprocess.run([sys.executable, "-c", _CHILD, cart_pole.__file__], env=env,
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]
    child = json.loads(done.stdout.strip().splitlines()[-1])
    assert child["ran"] == {name: "portable" for name in CASES}, child["ran"]
    assert (child["hits"], child["misses"], child["loops"]) == (1, 0, 0), child
    assert portable._index_state(glue._cache) == index
    for name in CASES:
        np.testing.assert_array_equal(np.array(child["q"][name]),
                                      _run(cart_pole, name, "specialized").q, err_msg=name)


def test_auto_runs_the_specialized_loop_until_the_controlled_glue_is_cached(cart_pole,
                                                                              monkeypatch):
    """jit="auto" with the portable controlled glue not cached runs the specialized loop (as
    before it existed) and starts the background compile of that glue; once the specialized
    loop of the controller is compiled in this process, auto keeps it (faster per step)."""
    started = []
    monkeypatch.setattr(portable, "portable_cached", lambda *args, **kwargs: False)
    monkeypatch.setattr(first_run, "start_background_compile",
                        lambda module, method, **kwargs: started.append((module, method, kwargs)))

    @numba.njit
    def fresh(t, q, qd, p):
        return -1.0 * q[1]

    first = lg.simulate(cart_pole, "midpoint", q0=Q0, t_end=0.05, h=H, control=fresh)
    assert first.jit == "specialized"
    assert started == [(cart_pole, "midpoint", {"controlled": True})]
    monkeypatch.undo()
    again = lg.simulate(cart_pole, "midpoint", q0=Q0, t_end=0.05, h=H, control=fresh)
    assert again.jit == "specialized"
    np.testing.assert_array_equal(again.q, first.q)


def test_the_background_compile_of_the_controlled_glue_is_asked_for(cart_pole, tmp_path,
                                                                     monkeypatch, capsys):
    """start_background_compile(controlled=True) starts `python -m lagrange_gen.jit.first_run
    <method> <module> <file> <lock> controlled` under a lock of its own, and that command
    compiles the controlled glue."""
    started = []

    def fake_spawn(argv, env):
        started.append(argv)
        return 999_999_999

    locks = []
    monkeypatch.setattr(first_run, "lock_path",
                        lambda method, controlled=False: locks.append(controlled) or
                        tmp_path / f"lock{controlled}")
    monkeypatch.setattr(first_run, "spawn_detached", fake_spawn)
    monkeypatch.setenv(first_run.BACKGROUND_ENV, "1")
    assert first_run.start_background_compile(cart_pole, "midpoint", controlled=True) is not None
    assert started[0][-1] == "controlled" and started[0][3] == "midpoint"
    assert locks == [True] and "run_midpoint_controlled in the background" in \
        capsys.readouterr().err
    asked = []
    monkeypatch.setattr(first_run, "compile_for_next_time",
                        lambda method, name, path, controlled=False: asked.append(controlled))
    (tmp_path / "l").write_text("1")
    first_run.main(["midpoint", "m", "f", str(tmp_path / "l"), "controlled"])
    first_run.main(["midpoint", "m", "f", str(tmp_path / "l")])
    assert asked == [True, False]


def test_the_controlled_lock_is_not_the_plain_one():
    assert first_run.lock_path("midpoint", True) != first_run.lock_path("midpoint")
    assert first_run.lock_path("midpoint", True).name.endswith("_controlled.compiling")


@numba.njit
def _raises_later(t, q, qd, p):
    if t > 0.05:
        raise ValueError("no input past 0.05")
    return 0.1


@pytest.mark.parametrize("jit", ["portable", "specialized"])
def test_a_controller_that_raises_is_one_line_naming_it(cart_pole, jit, capfd):
    """An exception cannot leave a hook called through a pointer (numba would print it and go
    on): the run stops at that step with one line naming the controller and its exception, in
    both loops."""
    with pytest.raises(lg.SimulationError) as err:
        lg.simulate(cart_pole, "midpoint", q0=Q0, t_end=0.2, h=H, control=_raises_later, jit=jit)
    text = str(err.value)
    assert "\n" not in text and "_raises_later" in text, text
    assert "ValueError: no input past 0.05" in text and "step 7 of 20" in text, text
    assert "Traceback" not in capfd.readouterr().err


def test_a_hook_writes_the_trailing_entries_of_p():
    """The one hook signature: a controller's hook and a Signal's write the last entries of
    p, whatever the model's parameters before them."""
    p = np.array([7.0, 8.0, 0.0, 0.0])
    none = np.zeros(0)

    @numba.njit
    def two(t, q, qd, p):
        return (1.5, t)

    hook = control.make_apply(two)
    assert hook(none, 2.0, none, none, p) and p.tolist() == [7.0, 8.0, 1.5, 2.0]
    assert not hook(none, 2.0, none, none, p)                     # unchanged: False
    signal = Signal([0.0, 1.0], [[1.0, 2.0], [3.0, 4.0]])
    assert control._signal_apply(control.signal_data(signal, 0.1), 1.0, none, none, p)
    assert p.tolist() == [7.0, 8.0, 3.0, 4.0]
    np.testing.assert_array_equal(signal(0.5), [1.0, 2.0])
