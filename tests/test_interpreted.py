"""The interpreted tier (lagrange_gen.jit.interpreted, run/fixed_driver.py) and the compile for
the next process (lagrange_gen.jit.first_run).

An interpreted run is the stepper library's own Python on the same arrays, so it must give the
compiled run's trajectory to round-off, for every fixed-step method (and the run-time branches a
model switches on: explicit time and work, constraints, nonsmooth elements, contacts,
nonholonomic rows, events), and it must compile nothing. The choice between interpreting and
compiling is tested with a fake compile cost; the background compile with a fake process where
only the lock and the switch are at stake, and once for real with fresh caches."""

import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from lagrange_gen.codegen import generate_model
from lagrange_gen.jit import compile_notice, first_run, folders, interpreted, portable
from lagrange_gen.run import fixed_driver
from lagrange_gen.run.loader import import_generated
from lagrange_gen.run.simulate import simulate
from lagrange_gen.steppers.core import registry
from lg_test_support import MODELS_DIR

EVENT_MODELS = Path(__file__).resolve().parent / "events" / "models"

# (method, model, q0, h, steps): every fixed-step method on a model with the branches it has
CASES = [(m, "driven_pendulum", [2.9], 1e-3, 25) for m in registry.METHODS
         if not (registry.spec(m).adaptive or registry.spec(m).constraints
                 or registry.spec(m).elements or registry.spec(m).contacts
                 or registry.spec(m).nonholonomic)]
CASES += [(m, "slider_crank", ([0.0, 1.3, 0.1], [1.8, 0.0, 0.0]), 1e-3, 25)
          for m in registry.CONSTRAINED_METHODS]
CASES += [("nonsmooth_euler", "prandtl", [0.0], 1e-2, 60)]
CASES += [("moreau_jean", "bouncing_ball", [0.02], 1e-3, 200)]       # lands within the run
# a rod constraint beside a wall contact, hit within the run (v0 on the rod's tangent)
CASES += [(m, "pendulum_wall_cartesian", ([0.45, -0.8930285549745876],
                                          [1.0, 0.5039032598602688]), 1e-3, 120)
          for m in ("spook_contacts", "moreau_jean")]
CASES += [(m, "chaplygin_sleigh", ([0.0, 0.0, 0.0], [0.3, 1.0, 2.0]), 1e-3, 25)
          for m in registry.NONHOLONOMIC_METHODS]
EVENT_CASES = [("verlet", "cart_pendulum_events", [0.3, 1.0], 1e-2, 60),
               ("rattle", "cartesian_pendulum_events", [np.sin(1.0), -np.cos(1.0)], 1e-2, 60)]


def test_every_fixed_step_method_is_covered():
    fixed = {m for m in registry.METHODS if not registry.spec(m).adaptive}
    assert fixed == {case[0] for case in CASES}


@pytest.fixture
def first_use(monkeypatch):
    """simulate(jit="auto") as in a process where numba has compiled nothing of the method (the
    interpreted tier's condition), no background compile; the compile expected is huge, so a
    run stays interpreted unless a test says otherwise."""
    monkeypatch.setattr(portable, "specialized_ready", lambda dispatcher, args: False)
    monkeypatch.setattr(portable, "portable_cached", lambda module, method: False)
    monkeypatch.setattr(fixed_driver, "_READY", {})
    monkeypatch.setattr(fixed_driver, "_INTERPRETED_S", {})
    monkeypatch.setattr(first_run, "expected_compile_seconds", lambda method: 1e9)
    monkeypatch.setenv(first_run.BACKGROUND_ENV, "0")
    monkeypatch.setenv(first_run.INTERPRETED_ENV, "1")


def _assert_close(a, b, rtol=1e-12):
    """Two trajectories equal to round-off: every saved field within rtol of the larger
    magnitude of the field (a component that passes through 0 is compared on its scale). The
    Newton iteration counts are compared only when rtol is 0: Newton stops on a test of
    increments near round-off, so where the compiled code rounds otherwise (numba may contract
    a * b + c) an iteration more or less is taken, and the state moves by up to newton_tol."""
    if rtol == 0.0:
        np.testing.assert_array_equal(a.newton_iters, b.newton_iters)
    for name in ("t", "q", "v", "energy"):
        x, y = np.asarray(getattr(a, name)), np.asarray(getattr(b, name))
        assert x.shape == y.shape, name
        np.testing.assert_allclose(x, y, rtol=0, atol=rtol * max(1.0, np.abs(y).max()),
                                   err_msg=name)
    assert a.saved.keys() == b.saved.keys()
    for name in a.saved:
        x, y = np.asarray(a.saved[name]), np.asarray(b.saved[name])
        scale = max(1.0, np.abs(y).max()) if y.size else 1.0
        np.testing.assert_allclose(x, y, rtol=0, atol=rtol * scale, err_msg=name)
    assert len(a.events) == len(b.events)
    for name in ("t", "q", "v"):
        if len(b.events):
            np.testing.assert_allclose(a.events[name], b.events[name], rtol=0,
                                       atol=max(rtol, 1e-12) * 100, err_msg=f"events {name}")


def _tolerance(method):
    """1e-12 for an explicit method; ten times Newton's tolerance (1e-12 relative) for an
    implicit one (see _assert_close): over a few steps its stops may fall otherwise."""
    return 1e-11 if registry.spec(method).implicit else 1e-12


def _interpreted_and_compiled(mod, method, q0, v0, h, steps):
    before = compile_notice.compiles()
    ours = simulate(mod, method, q0, v0, t_end=steps * h, h=h)
    assert ours.jit == "interpreted"
    assert compile_notice.compiles() == before          # nothing compiled for the steps
    return ours, simulate(mod, method, q0, v0, t_end=steps * h, h=h, jit="portable")


@pytest.mark.parametrize("method, stem, q0, h, steps", CASES, ids=[f"{c[0]}-{c[1]}" for c in CASES])
def test_interpreted_run_equals_the_compiled_one(generated, first_use, method, stem, q0, h,
                                                 steps):
    q0, v0 = q0 if isinstance(q0, tuple) else (q0, None)
    a, b = _interpreted_and_compiled(generated(stem), method, q0, v0, h, steps)
    assert len(a.t) == steps + 1
    assert not np.array_equal(b.q[0], b.q[-1])           # the run moved
    _assert_close(a, b, _tolerance(method))


@pytest.fixture(scope="module")
def event_module(tmp_path_factory):
    folder = tmp_path_factory.mktemp("interpreted_events")
    return lambda stem: import_generated(generate_model(EVENT_MODELS / f"{stem}.py", folder).path)


@pytest.mark.parametrize("method, stem, q0, h, steps", EVENT_CASES,
                         ids=[f"{c[0]}-{c[1]}" for c in EVENT_CASES])
def test_interpreted_run_locates_the_compiled_events(event_module, first_use, method, stem, q0,
                                                     h, steps):
    a, b = _interpreted_and_compiled(event_module(stem), method, q0, None, h, steps)
    assert len(b.events) > 0
    _assert_close(a, b, _tolerance(method))


def test_a_twin_calls_twins_and_keeps_the_code(generated):
    """The twin of a dispatcher is its py_func's code with globals and modules re-bound: a
    package module passed as a value becomes a module of twins; numpy stays numpy."""
    from lagrange_gen.steppers.methods import rk4
    step = interpreted.twin(rk4.step)
    assert step.__code__ is rk4.step.py_func.__code__
    assert interpreted.twin(rk4.step) is step                       # memoized
    assert step.__globals__["rk_step"].__code__ is rk4.rk_step.py_func.__code__
    module = interpreted.twin(rk4)
    assert module.step is step and module.SPEC is rk4.SPEC
    assert interpreted.twin(np) is np
    table = portable.kernel_table(generated("cart_pendulum"), "rk4")
    twin_table = interpreted.twin(table)
    assert type(twin_table) is type(table)
    assert twin_table.forward_dynamics.__code__ is table.forward_dynamics.dispatcher.py_func.__code__


def test_the_interpreted_tier_can_be_turned_off(generated, first_use, monkeypatch):
    monkeypatch.setenv(first_run.INTERPRETED_ENV, "0")
    run = simulate(generated("double_pendulum"), "verlet", [0.3, 0.2], None, t_end=0.01, h=1e-3)
    assert run.jit == "portable"


def test_a_short_run_never_compiles_in_the_foreground(generated, first_use, monkeypatch):
    """Ten steps fit in the first interpreted chunk: no compile, whatever the compile costs."""
    monkeypatch.setattr(first_run, "expected_compile_seconds", lambda method: 0.0)
    run = simulate(generated("double_pendulum"), "verlet", [0.3, 0.2], None, t_end=0.01, h=1e-3)
    assert run.jit == "interpreted"


def test_a_run_goes_on_compiled_once_its_interpreted_time_would_pass_the_compile(
        generated, first_use, monkeypatch):
    mod = generated("double_pendulum")
    monkeypatch.setattr(first_run, "expected_compile_seconds", lambda method: 0.0)
    switched = simulate(mod, "verlet", [0.3, 0.2], None, t_end=0.1, h=1e-3)
    first = fixed_driver.PROBE_STEPS
    assert switched.jit == f"interpreted, then portable from step {first}"
    compiled = simulate(mod, "verlet", [0.3, 0.2], None, t_end=0.1, h=1e-3, jit="portable")
    _assert_close(switched, compiled, _tolerance("verlet"))


def test_a_run_waits_for_the_compile_running_elsewhere(generated, first_use, monkeypatch):
    """Worth compiling, but a compile of the same glue holds its lock (the background one this
    run started): the run goes on interpreted instead of compiling the glue a second time
    beside it (twice the memory, half the speed each on two cores)."""
    mod = generated("double_pendulum")
    monkeypatch.setattr(first_run, "expected_compile_seconds", lambda method: 0.0)
    monkeypatch.setattr(first_run, "compile_running", lambda method: True)
    run = simulate(mod, "verlet", [0.3, 0.2], None, t_end=0.1, h=1e-3)
    assert run.jit == "interpreted" and len(run.t) == 101


def test_a_run_whose_interpreted_time_stays_below_the_compile_stays_interpreted(
        generated, first_use):
    run = simulate(generated("double_pendulum"), "verlet", [0.3, 0.2], None, t_end=0.1, h=1e-3)
    assert run.jit == "interpreted" and len(run.t) == 101


def test_the_choice_counts_the_interpreted_time_of_earlier_runs(first_use, monkeypatch):
    monkeypatch.setattr(first_run, "expected_compile_seconds", lambda method: 1.0)
    assert not fixed_driver._worth_compiling("rk4", 0.1, 10, 50)        # 0.5 s projected
    monkeypatch.setitem(fixed_driver._INTERPRETED_S, "rk4", 0.6)
    assert fixed_driver._worth_compiling("rk4", 0.1, 10, 50)            # 0.6 s spent + 0.5 s


def test_steps_python_cannot_run_run_again_compiled(generated, first_use, monkeypatch):
    """Where the Python twin raises (a division by zero numba turns into inf), the driver runs
    the same chunk compiled, from the same state."""
    mod = generated("double_pendulum")
    monkeypatch.setattr(portable, "interpreted_runner",
                        lambda module, method: lambda *args: interpreted.PYTHON_ONLY_FAILURE)
    run = simulate(mod, "midpoint", [0.3, 0.2], None, t_end=0.05, h=1e-3)
    assert run.jit == "interpreted, then portable from step 0"
    _assert_close(run, simulate(mod, "midpoint", [0.3, 0.2], None, t_end=0.05, h=1e-3,
                                jit="portable"), rtol=0.0)


def test_a_python_only_exception_becomes_the_failure_value():
    def divide(x):
        return 1.0 / x
    assert interpreted.run(divide, 0.0) is interpreted.PYTHON_ONLY_FAILURE
    assert interpreted.run(divide, 4.0) == 0.25


def test_expected_compile_seconds_default_and_record(tmp_path, monkeypatch):
    monkeypatch.setattr(folders, "portable_dir", lambda: tmp_path)
    assert first_run.expected_compile_seconds("rk4") == first_run.DEFAULT_COMPILE_S
    first_run.record_compile_seconds("rk4", 4.5)
    first_run.record_compile_seconds("verlet", 12.0)
    assert first_run.expected_compile_seconds("rk4") == 4.5
    assert json.loads((tmp_path / first_run.ESTIMATES_FILE).read_text()) == {"rk4": 4.5,
                                                                              "verlet": 12.0}
    (tmp_path / first_run.ESTIMATES_FILE).write_text("not json")
    assert first_run.expected_compile_seconds("rk4") == first_run.DEFAULT_COMPILE_S


class _FakeSpawn:
    """first_run.spawn_detached without a process: records the command, returns a pid no
    process has."""
    started = []

    def __call__(self, argv, env):
        _FakeSpawn.started.append(argv)
        return 999_999_999


def test_the_background_compile_can_be_turned_off(generated, tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(first_run, "lock_path", lambda method, controlled=False: tmp_path / "lock")
    monkeypatch.setattr(first_run, "spawn_detached", _FakeSpawn())
    _FakeSpawn.started = []
    monkeypatch.setenv(first_run.BACKGROUND_ENV, "0")
    assert first_run.start_background_compile(generated("cart_pendulum"), "rk4") is None
    assert _FakeSpawn.started == [] and not (tmp_path / "lock").exists()
    assert capsys.readouterr().err == ""


def test_the_background_compile_honours_its_lock(generated, tmp_path, monkeypatch, capsys):
    lock = tmp_path / "lock"
    monkeypatch.setattr(first_run, "lock_path", lambda method, controlled=False: lock)
    monkeypatch.setattr(first_run, "spawn_detached", _FakeSpawn())
    monkeypatch.setenv(first_run.BACKGROUND_ENV, "1")
    _FakeSpawn.started = []
    mod = generated("cart_pendulum")
    pid = first_run.start_background_compile(mod, "rk4")
    assert pid is not None and json.loads(lock.read_text())["pid"] == pid
    assert _FakeSpawn.started[0][1:4] == ["-m", "lagrange_gen.jit.first_run", "rk4"]
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "run_rk4 in the background" in err
    assert first_run.BACKGROUND_ENV in err
    lock.write_text(json.dumps(first_run.lock_record(os.getpid())))    # a live compile holds it
    assert first_run.start_background_compile(mod, "rk4") is None
    assert first_run.compile_running("rk4")
    assert len(_FakeSpawn.started) == 1
    lock.write_text(json.dumps(first_run.lock_record(999_999_999)))    # its process is gone
    assert not first_run.compile_running("rk4")
    assert first_run.start_background_compile(mod, "rk4") is not None
    assert len(_FakeSpawn.started) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "took over the stale lock" in err and "is gone" in err


def test_a_detached_process_is_no_child_of_ours(tmp_path):
    """spawn_detached: the process runs on (it writes its file), but it is not this process's
    child, so nothing is left for Python to report as still running when this one exits."""
    marker = tmp_path / "ran"
    code = f"import pathlib, time; time.sleep(0.5); pathlib.Path({str(marker)!r}).write_text('ok')"
    pid = first_run.spawn_detached([sys.executable, "-c", code], dict(os.environ))
    assert pid > 0
    with pytest.raises(ChildProcessError):
        os.waitpid(pid, os.WNOHANG)
    for _ in range(200):
        if marker.exists():
            break
        time.sleep(0.05)
    assert marker.read_text() == "ok"


def test_the_background_compile_fills_the_cache_for_the_next_process(tmp_path):
    """With empty caches: the compile process leaves numba's cache holding the portable glue of
    the method and the model's kernels, so that a new process runs its first simulate on them
    without compiling, and it records its seconds and releases its lock."""
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "numba"),
               LAGRANGE_GEN_PORTABLE_DIR=str(tmp_path / "portable"),
               **{first_run.BACKGROUND_ENV: "0", first_run.INTERPRETED_ENV: "1"})
    gen = tmp_path / "gen"
    path = generate_model(MODELS_DIR / "damped_oscillator.py", gen, methods=["explicit_euler"]).path
    child = ("import sys, json\n"
             "from lagrange_gen.jit import first_run, compile_notice\n"
             "from lagrange_gen.run.loader import import_generated\n"
             "from lagrange_gen.run.simulate import simulate\n"
             "mod = import_generated(sys.argv[1])\n"
             "lock = first_run.lock_path('explicit_euler')\n"
             "if sys.argv[2] == 'compile':\n"
             "    assert first_run.take_lock(lock)\n"
             "    first_run.main(['explicit_euler', mod.__name__, mod.__file__, str(lock)])\n"
             "    print(json.dumps([lock.exists(), first_run.expected_compile_seconds("
             "'explicit_euler')]))\n"
             "else:\n"
             "    traj = simulate(mod, 'explicit_euler', [0.1], None, t_end=0.01, h=1e-3)\n"
             "    print(json.dumps([traj.jit, compile_notice.compiles()]))\n")

    def run(what):
        done = subprocess.run([sys.executable, "-c", child, str(path), what], env=env,
                              capture_output=True, text=True, timeout=600)
        assert done.returncode == 0, done.stderr[-2000:]
        return json.loads(done.stdout.strip().splitlines()[-1])

    assert run("simulate") == ["interpreted", 0]           # before: nothing cached
    locked, seconds = run("compile")
    assert not locked and seconds != first_run.DEFAULT_COMPILE_S and seconds > 0
    assert run("simulate") == ["portable", 0]
