"""The portable glue (lagrange_gen.jit.portable): one compiled stepper for every model.

A portable run is the specialized run's floating-point operations in the same order, with the
kernels called through pointers instead of inlined: its trajectory must equal the specialized
one bit for bit, for every method (including the branches a model switches on at run time:
explicit time and T1, constraints, nonsmooth elements, events). Its numba type must not depend
on the model, or it would compile again for every model, which is what it is for."""

from pathlib import Path

import numpy as np
import pytest

from lagrange_gen.codegen import generate_model
from lagrange_gen.codegen import glue
from lagrange_gen.errors import SimulationError
from lagrange_gen.jit import portable
from lagrange_gen.run import fixed_driver as fixed_run
from lagrange_gen.run.loader import import_generated
from lagrange_gen.run.simulate import simulate
from lagrange_gen.steppers.core import registry
from lagrange_gen.steppers.core.method_spec import make_settings

EVENT_MODELS = Path(__file__).resolve().parent / "events" / "models"

# (method, model, q0, h, t_end): every method once, on a model that exercises the run-time
# branches it has: driven_pendulum (explicit time, T1 = b . qd, the work W), slider_crank
# (rheonomic constraints), prandtl (nonsmooth elements), bouncing_ball (contacts),
# chaplygin_sleigh (nonholonomic constraints), the events models of tests/events.
CASES = [(m, "driven_pendulum", [2.9], 1e-3, 0.2) for m in registry.METHODS
         if not (registry.spec(m).constraints or registry.spec(m).elements
                 or registry.spec(m).contacts or registry.spec(m).nonholonomic)]
CASES += [(m, "slider_crank", ([0.0, 1.3, 0.1], [1.8, 0.0, 0.0]), 1e-3, 0.1)
          for m in registry.CONSTRAINED_METHODS]
CASES += [("nonsmooth_euler", "prandtl", [0.0], 1e-3, 2.0)]
CASES += [("moreau_jean", "bouncing_ball", [1.0], 1e-3, 1.5),
          ("dop853_impacts", "bouncing_ball", [1.0], None, 4.5)]
CASES += [(m, "chaplygin_sleigh", ([0.0, 0.0, 0.0], [0.3, 1.0, 2.0]), 1e-3, 1.0)
          for m in registry.NONHOLONOMIC_METHODS]
EVENT_CASES = [("verlet", "cart_pendulum_events", [0.3, 1.0], 1e-3, 3.0),
               ("dop853", "cart_pendulum_events", [0.3, 1.0], None, 3.0),
               ("rattle", "cartesian_pendulum_events", [np.sin(1.0), -np.cos(1.0)], 1e-3, 3.0)]


@pytest.fixture(scope="module")
def event_module(tmp_path_factory):
    folder, modules = tmp_path_factory.mktemp("portable_events"), {}

    def get(stem):
        if stem not in modules:
            modules[stem] = import_generated(generate_model(EVENT_MODELS / f"{stem}.py",
                                                            folder).path)
        return modules[stem]
    return get


def _assert_same(a, b):
    for name in ("t", "q", "v", "energy", "newton_iters", "newton_residual"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)
    assert a.saved.keys() == b.saved.keys()
    for name in a.saved:
        np.testing.assert_array_equal(a.saved[name], b.saved[name], err_msg=name)
    if a.work is not None or b.work is not None:
        np.testing.assert_array_equal(a.work, b.work, err_msg="work")
    assert len(a.events) == len(b.events)
    np.testing.assert_array_equal(a.events, b.events, err_msg="events")


def _both(mod, method, q0, v0, h, t_end):
    kwargs = dict(t_end=t_end, h=h)
    portable_run = simulate(mod, method, q0, v0, jit="portable", **kwargs)
    specialized_run = simulate(mod, method, q0, v0, jit="specialized", **kwargs)
    assert portable_run.jit == "portable" and specialized_run.jit == "specialized"
    return portable_run, specialized_run


@pytest.mark.parametrize("method, stem, q0, h, t_end", CASES, ids=[c[0] for c in CASES])
def test_portable_run_equals_specialized_bit_for_bit(generated, method, stem, q0, h, t_end):
    q0, v0 = q0 if isinstance(q0, tuple) else (q0, None)
    a, b = _both(generated(stem), method, q0, v0, h, t_end)
    assert len(a.t) > 10
    _assert_same(a, b)


@pytest.mark.parametrize("method, stem, q0, h, t_end", EVENT_CASES,
                         ids=[f"{c[0]}-{c[1]}" for c in EVENT_CASES])
def test_portable_events_equal_specialized(event_module, method, stem, q0, h, t_end):
    mod = event_module(stem)
    assert mod.N_EVENTS > 0
    a, b = _both(mod, method, q0, None, h, t_end)
    assert len(a.events) > 0
    _assert_same(a, b)


def test_one_compile_serves_every_model(generated):
    """The portable verlet runs three models with one compiled signature."""
    for stem, q0 in (("cart_pendulum", [0.1, 1.0]), ("double_pendulum", [0.3, 0.2]),
                     ("kepler", [1.0, 0.0])):
        v0 = [0.0, 1.1] if stem == "kepler" else None
        simulate(generated(stem), "verlet", q0, v0, t_end=0.01, h=1e-3, jit="portable")
    assert len(portable._glue_module("verlet").run_verlet.overloads) == 1


def test_auto_switches_to_the_specialized_loop_on_a_long_run(generated, monkeypatch):
    mod = generated("double_pendulum")
    monkeypatch.setattr(fixed_run, "CHUNK_STEPS", 100)
    monkeypatch.setattr(fixed_run, "SPECIALIZE_AFTER_S", 0.0)
    monkeypatch.setattr(fixed_run, "SPECIALIZED_PER_NATIVE_S", 0.0)
    monkeypatch.setattr(portable, "specialized_ready", lambda dispatcher, args: False)
    monkeypatch.setattr(fixed_run, "_READY", {})     # no choice remembered from another test
    auto = simulate(mod, "symplectic_euler", [0.3, 0.2], None, t_end=0.5, h=1e-3)
    assert auto.jit == "portable, then specialized from step 100"
    specialized = simulate(mod, "symplectic_euler", [0.3, 0.2], None, t_end=0.5, h=1e-3,
                           jit="specialized")
    _assert_same(auto, specialized)


def test_auto_keeps_portable_when_the_specialized_compile_cannot_pay(generated, monkeypatch):
    """A model whose native kernels took long to compile (a large robot) keeps the portable loop
    on a run whose saving (SPECIALIZED_GAIN of it) stays below numba's compile of the same
    kernels (SPECIALIZED_PER_NATIVE_S times the native seconds): minutes and gigabytes for a
    few per cent per step."""
    mod = generated("double_pendulum")
    monkeypatch.setattr(fixed_run, "CHUNK_STEPS", 100)
    monkeypatch.setattr(fixed_run, "SPECIALIZE_AFTER_S", 0.0)
    monkeypatch.setattr(portable, "specialized_ready", lambda dispatcher, args: False)
    monkeypatch.setattr(portable, "native_compile_seconds", lambda module, method: 30.0)
    monkeypatch.setattr(fixed_run, "_READY", {})
    run = simulate(mod, "symplectic_euler", [0.3, 0.2], None, t_end=0.5, h=1e-3)
    assert run.jit == "portable"


def test_the_specialized_compile_is_weighed_by_the_native_one():
    worth = fixed_run._worth_specializing
    # 100 of 10,000 steps in 1 s: 99 s to go
    assert worth(1.0, 100, 10_000, None)                    # not known: the time alone
    assert worth(1.0, 100, 10_000, 0.5)                     # 9.9 s saved > 5 s of numba
    assert not worth(1.0, 100, 10_000, 20.0)                # a humanoid: 200 s of numba
    assert not worth(0.1, 100, 10_000, 0.0)                 # 9.9 s to go: below a minute
    assert worth(1.0, 100, 1_000_000, 20.0)                 # 2.8 hours to go


def test_native_compile_seconds_are_recorded(generated, monkeypatch, tmp_path):
    """The seconds LLVM took come back with the object code: a later process weighs the
    specialized compile by them without compiling anything."""
    from lagrange_gen.jit import native
    monkeypatch.setenv("LAGRANGE_GEN_PORTABLE_DIR", str(tmp_path))
    monkeypatch.setattr(native, "_KERNELS", {})
    mod = generated("cart_pendulum")
    first = native.native_kernel(mod, "energy", portable.native_dir())
    monkeypatch.setattr(native, "_KERNELS", {})
    again = native.native_kernel(mod, "energy", portable.native_dir())
    assert again.cached and first.compile_seconds > 0
    assert again.compile_seconds == pytest.approx(first.compile_seconds, abs=1e-4)


def test_auto_keeps_portable_on_a_short_run(generated, monkeypatch):
    monkeypatch.setattr(fixed_run, "CHUNK_STEPS", 100)
    monkeypatch.setattr(portable, "specialized_ready", lambda dispatcher, args: False)
    monkeypatch.setattr(fixed_run, "_READY", {})     # no choice remembered from another test
    run = simulate(generated("double_pendulum"), "symplectic_euler", [0.3, 0.2], None,
                   t_end=0.5, h=1e-3)
    assert run.jit == "portable"


def test_auto_runs_the_specialized_loop_once_it_is_compiled(generated):
    mod = generated("double_pendulum")
    simulate(mod, "rk4", [0.3, 0.2], None, t_end=0.01, h=1e-3, jit="specialized")
    assert simulate(mod, "rk4", [0.3, 0.2], None, t_end=0.01, h=1e-3).jit == "specialized"


def test_specialized_ready_is_false_before_any_compile(tmp_path):
    mod = import_generated(generate_model(Path(__file__).resolve().parent.parent / "models"
                                          / "damped_oscillator.py", tmp_path,
                                          methods=["explicit_euler"]).path)
    q = np.zeros(mod.N_COORDS)
    args = fixed_run.warm_up_args(q, q, 0.0, 1e-3, mod.DEFAULT_PARAMS.copy(),
                                  make_settings(registry.spec("explicit_euler"), {}),
                                  np.zeros((1, 0)), np.zeros(2 * mod.N_COORDS + 4),
                                  np.zeros((0, 3 + 2 * mod.N_COORDS)))
    assert not portable.specialized_ready(mod.run_explicit_euler, args)
    mod.run_explicit_euler(*args)
    assert portable.specialized_ready(mod.run_explicit_euler, args)


def test_specialized_ready_remembers_a_miss_until_the_cache_index_changes(tmp_path, monkeypatch):
    """simulate asks on every call; the on-disk cache is read again only when its index changed
    (another process may have compiled the glue meanwhile), and a hit is still found then."""
    mod = import_generated(generate_model(Path(__file__).resolve().parent.parent / "models"
                                          / "damped_oscillator.py", tmp_path,
                                          methods=["explicit_euler"]).path)
    run = mod.run_explicit_euler
    q = np.zeros(mod.N_COORDS)
    args = fixed_run.warm_up_args(q, q, 0.0, 1e-3, mod.DEFAULT_PARAMS.copy(),
                                  make_settings(registry.spec("explicit_euler"), {}),
                                  np.zeros((1, 0)), np.zeros(2 * mod.N_COORDS + 4),
                                  np.zeros((0, 3 + 2 * mod.N_COORDS)))
    probes, stamp = [], [None]
    load = run._cache.load_overload
    monkeypatch.setattr(run._cache, "load_overload", lambda *a: probes.append(1) or load(*a))
    monkeypatch.setattr(portable, "_index_state", lambda cache: ("index", stamp[0]))
    for _ in range(3):
        assert not portable.specialized_ready(run, args)
    assert probes == []                      # no index file: no entry, numba is not asked
    stamp[0] = (1, 2)                        # the index was written
    for _ in range(3):
        assert not portable.specialized_ready(run, args)
    assert len(probes) == 1
    stamp[0] = (1, 3)                        # and written again
    assert not portable.specialized_ready(run, args)
    assert len(probes) == 2
    run(*args)                               # compiled (and saved) in this process
    assert portable.specialized_ready(run, args)


def test_a_kernel_table_is_typed_once_as_numba_types_any_tuple(generated):
    """The glue's arguments are typed on every call; a kernel table's type is numba's own tuple
    type, computed on its first call only."""
    from numba.core.typing.typeof import Purpose, _TypeofContext, typeof, typeof_impl
    table = portable.kernel_table(generated("cart_pendulum"), "rk4")
    first = typeof(table, Purpose.argument)
    assert portable._TABLE_TYPES[id(table)] == (table, first)      # kept for the next call
    assert typeof(table, Purpose.argument) is first
    assert first == typeof_impl.dispatch(tuple)(table, _TypeofContext(Purpose.argument))
    assert str(first).startswith("Kernels_rk4(")


def test_unknown_jit_is_refused(generated):
    with pytest.raises(SimulationError, match="jit='fast'.*auto, specialized, portable"):
        simulate(generated("cart_pendulum"), "rk4", [0.1, 1.0], None, t_end=0.01, h=1e-3,
                 jit="fast")


def test_glue_source_is_deterministic_and_names_its_library_version():
    a = glue.portable_glue_source("rattle", "0123456789abcdef")
    assert a == glue.portable_glue_source("rattle", "0123456789abcdef")
    assert "0123456789abcdef" in a and "def run_rattle(kern, n_saved, q0, v0" in a


@pytest.mark.parametrize("method, stem", [("verlet", "double_pendulum"),
                                          ("rattle", "cartesian_pendulum")])
def test_portable_ensemble_equals_the_generated_one(generated, method, stem):
    """ensemble_<method> of the portable glue against the generated module's, member by member,
    bit for bit (3 members of different starts; rattle projects them onto the constraint)."""
    import lagrange_gen as lg
    mod = generated(stem)
    q0 = np.array([[0.3, 0.2], [0.5, -0.4], [1.0, 0.1]])
    if stem == "cartesian_pendulum":
        q0 = np.stack([np.sin(q0[:, 0]), -np.cos(q0[:, 0])], axis=1)
    runs = {jit: lg.ensemble(mod, method, q0=q0, t_end=0.2, h=1e-3, save_every=10, jit=jit)
            for jit in ("portable", "specialized")}
    assert [r.jit for r in runs.values()] == ["portable", "specialized"]
    a, b = runs["portable"], runs["specialized"]
    assert a.ok.all() and b.ok.all()
    for name in ("q", "v", "energy", "newton_iters", "newton_residual"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)
    for name in a.saved:
        np.testing.assert_array_equal(a.saved[name], b.saved[name], err_msg=name)


def test_portable_ensemble_refuses_a_model_with_events(event_module):
    import lagrange_gen as lg
    mod = event_module("cart_pendulum_events")
    with pytest.raises(SimulationError, match="no event code.*jit='auto' or 'specialized'"):
        lg.ensemble(mod, "verlet", q0=np.array([[0.3, 1.0]]), t_end=0.01, h=1e-3, jit="portable")


def test_library_versions_unused_for_long_are_removed_when_a_new_one_is_made(tmp_path):
    import os
    import time
    old = time.time() - (portable.UNUSED_DAYS + 1) * 86400
    recent = time.time() - (portable.UNUSED_DAYS - 1) * 86400
    versions = {name: tmp_path / name for name in ("0123456789abcdef", "fedcba9876543210",
                                                   "00000000000000aa", "not-a-version-dir")}
    for folder in versions.values():
        (folder / "__pycache__").mkdir(parents=True)
        (folder / "run_verlet.py").write_text("# glue\n")
    os.utime(versions["0123456789abcdef"], (old, old))
    os.utime(versions["not-a-version-dir"], (old, old))
    os.utime(versions["fedcba9876543210"], (recent, recent))
    current = tmp_path / "00000000000000aa"
    os.utime(current, (old, old))                      # the one being made is never removed
    removed = portable.remove_unused_versions(current)
    assert removed == [versions["0123456789abcdef"]]
    assert not versions["0123456789abcdef"].exists()
    assert all(versions[name].exists() for name in ("fedcba9876543210", "00000000000000aa",
                                                      "not-a-version-dir"))


def test_using_a_library_version_marks_it_used(tmp_path, monkeypatch):
    import os
    monkeypatch.setenv(portable.DIR_ENV, str(tmp_path))
    portable._glue_module.cache_clear()
    try:
        portable._glue_module("explicit_euler")
        folder = tmp_path / portable.library_hash("explicit_euler")
        assert (folder / "run_explicit_euler.py").is_file()
        os.utime(folder, (0, 0))
        portable._glue_module.cache_clear()
        portable._glue_module("explicit_euler")
        assert os.stat(folder).st_mtime > 86400
    finally:
        portable._glue_module.cache_clear()
