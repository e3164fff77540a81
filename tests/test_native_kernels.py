"""Native kernels (lagrange_gen.jit.native): generated kernels lowered to LLVM IR and compiled by
llvmlite, called by the portable glue in place of numba-compiled kernels.

They must compute what the printed Python computes (the harness, tests/harness, checks them
against an independent reference on random models of the whole grammar; here: every kernel of
shipped models, planar and 3D, against the same source run as Python), have the signature numba
gives the same kernel (or the portable glue would compile again), come back from the object
cache, survive a corrupt cache file, and hand a kernel they cannot lower to numba with one line.
"""

import json
import os
import types
import warnings

import numpy as np
import pytest

from harness.check import _caller, pure_kernels
from lagrange_gen.jit.kernel_abi import argument_shapes, kernel_dimensions
from lagrange_gen.jit import native, portable
from lagrange_gen.jit.native_ir import Unsupported

#: Shipped models whose kernels cover the kinds a model can have: planar (cart pendulum),
#: rheonomic T1 and work (driven pendulum), holonomic constraints (slider crank, four bar),
#: contacts with a constant mass matrix (bouncing ball, puck on a table: 3D friction),
#: nonsmooth elements (prandtl), velocity constraints (chaplygin sleigh, the rolling disk),
#: a 3D rigid body (heavy top) and a 3D robot built from bodies (UR5: recursive kernels).
MODELS = ["cart_pendulum", "driven_pendulum", "slider_crank", "four_bar", "bouncing_ball",
          "puck_on_table", "prandtl", "chaplygin_sleigh", "rolling_disk", "heavy_top", "ur5"]


def _inputs(mod, name, rng):
    """Arguments of kernel ``name`` of ``mod``: random states in [-1, 1], parameters near their
    defaults, outputs filled with the same random numbers for both calls (a kernel that leaves
    an entry unwritten leaves it equal)."""
    shapes = argument_shapes(name, kernel_dimensions(vars(mod)))
    args = []
    for arg, shape in shapes:
        if shape is None:
            args.append(0.37)
        elif arg == "p":
            p = np.array([1.3 if d is None else d for d in mod.DEFAULTS], dtype=float)
            args.append(p * rng.uniform(0.9, 1.1, p.shape))
        else:
            args.append(rng.uniform(-1.0, 1.0, shape))
    return args


def _kernel_names(mod):
    return [k for k in (*mod.KERNELS, "forward_dynamics", "inverse_dynamics", "gravity_forces",
                        "bias_forces", "forward_dynamics_torques")
            if hasattr(mod, k) and argument_shapes(k, kernel_dimensions(vars(mod))) is not None]


def _same(got, expected):
    """Equal to rounding: the same operations in the same order give the same bits, but for
    the C library's pow against repeated multiplication of an integer power."""
    got, expected = np.asarray(got, dtype=float), np.asarray(expected, dtype=float)
    assert np.array_equal(np.isnan(got), np.isnan(expected))
    scale = max(1.0, float(np.nanmax(np.abs(expected)))) if expected.size else 1.0
    assert np.nanmax(np.abs(got - expected), initial=0.0) <= 1e-13 * scale


@pytest.mark.parametrize("stem", MODELS)
def test_native_kernels_equal_the_printed_python(stem, generated):
    _check_every_kernel(generated(stem))


@pytest.mark.parametrize("stem", ["ur5", "bicycle", "slider_crank"])
def test_kernels_lowered_in_pieces_equal_the_printed_python(stem, generated, monkeypatch):
    """Long runs of assignments become functions of their own (native_ir._statements): with
    pieces of a few statements, every boundary case (a value crossing several pieces, a name
    assigned again in a later piece, inputs stored once before a column loop) is exercised."""
    from lagrange_gen.jit import native_ir
    monkeypatch.setattr(native_ir, "CHUNK_STATEMENTS", 7)
    monkeypatch.setattr(native_ir, "LOOP_CHUNK_STATEMENTS", 3)
    monkeypatch.setattr(native, "_KERNELS", {})
    _check_every_kernel(generated(stem))


def _check_every_kernel(mod):
    python = pure_kernels(mod)
    rng = np.random.default_rng(7)
    names = _kernel_names(mod)
    assert "forward_dynamics" in names
    for name in names:
        kernel = native.native_kernel(mod, name, portable.native_dir())
        for _ in range(2):
            args = _inputs(mod, name, rng)
            mine = [a.copy() if isinstance(a, np.ndarray) else a for a in args]
            theirs = [a.copy() if isinstance(a, np.ndarray) else a for a in args]
            got = _caller(len(mine))(kernel, *mine)
            expected = getattr(python, name)(*theirs)
            if expected is None:
                assert got is None, name
            else:
                _same(got, expected)
            for a, b in zip(mine, theirs):
                if isinstance(a, np.ndarray):
                    _same(a, b)


def test_native_signature_is_numbas(generated):
    """The portable glue's type holds each kernel's signature: a native kernel typed otherwise
    than numba types the same kernel would compile the glue again (or call it wrongly)."""
    mod = generated("bouncing_ball")
    function_kernel = portable._function_kernel_class()
    for name in ("forward_dynamics", "energy", "contacts", "events", "mass_matrix"):
        assert native.native_kernel(mod, name, portable.native_dir()).signature() == \
            function_kernel(getattr(mod, name)).signature(), name


def _fresh(monkeypatch, tmp_path):
    """An empty object cache and no kernel remembered in this process."""
    monkeypatch.setenv("LAGRANGE_GEN_PORTABLE_DIR", str(tmp_path))
    monkeypatch.setattr(native, "_KERNELS", {})


def test_object_cache_is_reused_and_a_corrupt_file_is_compiled_again(generated, monkeypatch,
                                                                     tmp_path):
    mod = generated("cart_pendulum")
    _fresh(monkeypatch, tmp_path)
    rng = np.random.default_rng(3)
    args = _inputs(mod, "forward_dynamics", rng)

    def run(kernel):
        mine = [a.copy() if isinstance(a, np.ndarray) else a for a in args]
        status = _caller(len(mine))(kernel, *mine)
        return status, mine[-1]

    first = native.native_kernel(mod, "forward_dynamics", portable.native_dir())
    assert not first.cached
    objects = sorted(portable.native_dir().glob("*.o"))
    assert len(objects) == 1
    monkeypatch.setattr(native, "_KERNELS", {})
    again = native.native_kernel(mod, "forward_dynamics", portable.native_dir())
    assert again.cached and again.key == first.key
    expected = run(first)
    assert run(again)[0] == expected[0] and np.array_equal(run(again)[1], expected[1])
    # a truncated object (a process killed while copying a cache, a full disk) is not loaded
    objects[0].write_bytes(objects[0].read_bytes()[:100])
    monkeypatch.setattr(native, "_KERNELS", {})
    repaired = native.native_kernel(mod, "forward_dynamics", portable.native_dir())
    assert not repaired.cached
    assert np.array_equal(run(repaired)[1], expected[1])
    meta = json.loads(objects[0].with_suffix(".json").read_text())
    assert meta["kernel"] == "forward_dynamics" and meta["ret"] == "i"


def test_a_changed_kernel_is_a_new_key(generated, monkeypatch, tmp_path):
    """The key covers the kernel's source and the constants it reads: a module constant with
    another value (MASS_FACTOR of other default parameters, SINGULAR_RTOL) is another object."""
    mod = generated("bouncing_ball")
    _fresh(monkeypatch, tmp_path)
    before = native.native_kernel(mod, "forward_dynamics", portable.native_dir()).key
    changed = types.ModuleType(mod.__name__ + "_changed")
    changed.__dict__.update(vars(mod))
    # the same function source, reading another constant factor
    fn = mod.forward_dynamics.py_func
    scope = dict(fn.__globals__, MASS_FACTOR=2.0 * mod.MASS_FACTOR)
    changed.forward_dynamics = types.FunctionType(fn.__code__, scope, fn.__name__)
    assert native.native_kernel(changed, "forward_dynamics", portable.native_dir()).key != before


_OUTSIDE = '''
import math


def loop_kernel(q, t, p, out):
    k = 0
    while k < 2:
        out[k] = math.sin(q[k]) * p[0]
        k += 1
'''


def test_a_kernel_outside_the_subset_is_compiled_by_numba_with_one_line(tmp_path, monkeypatch):
    """A construct native_ir does not lower (here a while loop) is refused by name and line,
    and the portable table gets numba's kernel instead: the same numbers, one warning."""
    import importlib.util
    from lagrange_gen.jit import njit, KERNEL_OPTIONS
    path = tmp_path / "outside_kernels.py"
    path.write_text(_OUTSIDE)
    spec = importlib.util.spec_from_file_location("outside_kernels", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    mod.NAME = "outside"
    mod.loop_kernel = njit(**dict(KERNEL_OPTIONS, cache=False))(mod.loop_kernel)
    with pytest.raises(Unsupported, match=r"loop_kernel, line 3 of its source: statement While"):
        native.native_kernel(mod, "loop_kernel", portable.native_dir())
    monkeypatch.setattr(native, "_WARNED", set())
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        kernel = portable.table_kernel(mod, "loop_kernel")
    lines = [str(w.message) for w in caught]
    assert len(lines) == 1 and "outside.loop_kernel compiled by numba" in lines[0], lines
    assert "\n" not in lines[0]
    assert isinstance(kernel, portable._function_kernel_class())
    q, out = np.array([0.3, -0.2]), np.zeros(2)
    _caller(4)(kernel, q, 0.0, np.array([2.0]), out)
    assert np.array_equal(out, 2.0 * np.sin(q))


def test_a_junk_optimization_level_says_so_once(monkeypatch):
    monkeypatch.setattr(native, "_WARNED", set())
    monkeypatch.setenv(native.OPT_ENV, "fast")
    with pytest.warns(RuntimeWarning, match=r"LAGRANGE_GEN_NATIVE_OPT='fast' is not 0, 1, 2 or 3"):
        assert native.opt_level() == native.OPT_LEVEL
    monkeypatch.setenv(native.OPT_ENV, "2")
    assert native.opt_level() == 2


def test_native_off_uses_numba(generated, monkeypatch):
    mod = generated("cart_pendulum")
    monkeypatch.setenv(native.NATIVE_ENV, "0")
    assert isinstance(portable.table_kernel(mod, "energy"), portable._function_kernel_class())
    monkeypatch.setenv(native.NATIVE_ENV, "1")
    assert portable.table_kernel(mod, "energy").__class__.__name__ == "NativeKernel"


def test_portable_tables_hold_native_kernels(generated):
    """The path a first run takes: the kernel table of the portable glue holds native kernels
    (no numba compile of the model's kernels) for a method's every kernel."""
    mod = generated("slider_crank")
    table = portable.kernel_table(mod, "rattle")
    kernels = [getattr(table, f) for f in table._fields if not f.isupper()]
    assert kernels and all(k.__class__.__name__ == "NativeKernel" for k in kernels)


def test_kernels_called_from_python_compile_nothing_with_numba(tmp_path, monkeypatch):
    """A generated module's kernels called from Python (accelerations, a kernel called by hand,
    the energy check after a run) run their native twins through jit/native_calls.py: numba
    compiles none of the model's kernels, and the numbers are those of numba's kernels."""
    from lagrange_gen.codegen import generate_model
    from lagrange_gen.jit.python_calls import unchecked
    from lagrange_gen.run.loader import import_generated
    from lg_test_support import MODELS_DIR
    path = generate_model(MODELS_DIR / "double_pendulum.py", tmp_path, methods=["rk4"]).path
    mod = import_generated(path)
    q, qd, p = np.array([0.3, -0.4]), np.array([0.2, 0.7]), mod.DEFAULT_PARAMS.copy()
    acc = mod.accelerations(q, qd)
    energy = mod.energy(q, qd, 0, p)                     # an int t, as a user may pass
    rows = unchecked(mod.energy)(q, qd, 0.0, p)
    H = np.zeros((2, 2))
    status = mod.forward_dynamics(q, qd, 0.0, p, H, np.zeros(2))
    kernels = [getattr(mod, k) for k in mod.KERNELS] + [mod.forward_dynamics]
    assert all(not k.overloads for k in kernels)          # numba compiled none of them
    # numba's own kernels give the same numbers
    base = type(mod.energy).unchecked_base
    assert base.__call__(mod.energy, q, qd, 0.0, p) == energy == rows
    qdd = np.zeros(2)
    assert base.__call__(mod.forward_dynamics, q, qd, 0.0, p, np.zeros((2, 2)), qdd) == status
    np.testing.assert_array_equal(acc, qdd)


def test_a_strided_argument_from_python_goes_to_numba(generated):
    """Native kernels take C-contiguous writable arrays; any other layout numba takes."""
    mod = generated("double_pendulum")
    q2 = np.array([[0.3, 9.0], [-0.4, 9.0]])[:, 0]       # a column: not contiguous
    q = np.ascontiguousarray(q2)
    qd, p = np.array([0.2, 0.7]), mod.DEFAULT_PARAMS
    assert mod.energy(q2, qd, 0.0, p) == mod.energy(q, qd, 0.0, p)


def _tiered(monkeypatch, tmp_path):
    """An empty object cache, background compiles allowed, every kernel 'big'."""
    _fresh(monkeypatch, tmp_path)
    monkeypatch.setenv("LAGRANGE_GEN_BACKGROUND_COMPILE", "1")
    monkeypatch.delenv("LAGRANGE_GEN_NATIVE_OPT", raising=False)
    monkeypatch.setattr(native, "FAST_FIRST_BYTES", 0)


def _outputs(kernel, args):
    mine = [a.copy() if isinstance(a, np.ndarray) else a for a in args]
    result = _caller(len(mine))(kernel, *mine)
    return result, [a for a in mine if isinstance(a, np.ndarray)]


def test_a_big_kernel_runs_at_level_0_first_then_at_level_1_equal_bits(generated, monkeypatch,
                                                                     tmp_path):
    """With its level-1 object not cached, a big kernel is compiled at LLVM's level 0 (fast) and
    wants level 1; the background compile (run here in this process) writes the level-1 object,
    which the next lookup loads. Both levels give the same bits: no fast-math, the same
    operations in the same order."""
    from lagrange_gen.jit import native_background
    mod = generated("ur5")
    _tiered(monkeypatch, tmp_path)
    folder = portable.native_dir()
    names = ("forward_dynamics", "rhs_jacobian", "energy")
    first = [native.native_kernel(mod, name, folder) for name in names]
    assert [(k.level, k.wanted, k.cached) for k in first] == [(0, 1, False)] * 3
    started = []     # the "background process" is this one: a live process holds the lock
    monkeypatch.setattr(native_background, "spawn_detached",
                        lambda argv, env: started.append(argv) or os.getpid())
    assert native_background.compile_later(mod, first, folder) == os.getpid()
    argv = started[0]
    assert argv[argv.index("-m") + 1] == "lagrange_gen.jit.native_background"
    assert sorted(argv[-3:]) == sorted(names)
    # a second run while that compile holds the module's lock starts none
    assert native_background.compile_later(mod, first, folder) is None
    native_background.release_lock(native_background.lock_path(mod, folder))
    native_background.compile_kernels(mod.__name__, mod.__file__, folder, 1, list(names))
    monkeypatch.setattr(native, "_KERNELS", {})
    best = [native.native_kernel(mod, name, folder) for name in names]
    assert [(k.level, k.cached) for k in best] == [(1, True)] * 3
    rng = np.random.default_rng(5)
    for fast, slow in zip(first, best):
        args = _inputs(mod, fast.name, rng)
        (r0, out0), (r1, out1) = _outputs(fast, args), _outputs(slow, args)
        assert r0 == r1 and all(np.array_equal(a, b) for a, b in zip(out0, out1)), fast.name
    # a new process before the background compile ends finds the level-0 object
    (folder / f"{best[2].key}.json").unlink()
    monkeypatch.setattr(native, "_KERNELS", {})
    again = native.native_kernel(mod, "energy", folder)
    assert (again.level, again.wanted, again.cached) == (0, 1, True)


@pytest.mark.parametrize("setting", ["background off", "explicit level"])
def test_no_level_0_first_without_background_compiles_or_with_an_explicit_level(
        setting, generated, monkeypatch, tmp_path):
    """With nothing to compile the better object later (background compiles off), or a level
    asked for by $LAGRANGE_GEN_NATIVE_OPT, the kernel is compiled at that level at once."""
    mod = generated("cart_pendulum")
    _tiered(monkeypatch, tmp_path)
    if setting == "background off":
        monkeypatch.setenv("LAGRANGE_GEN_BACKGROUND_COMPILE", "0")
    else:
        monkeypatch.setenv("LAGRANGE_GEN_NATIVE_OPT", "1")
    kernel = native.native_kernel(mod, "forward_dynamics", portable.native_dir())
    assert (kernel.level, kernel.wanted) == (1, 1)


def test_the_background_compile_of_kernels_runs_detached_and_leaves_level_1_objects(
        generated, monkeypatch, tmp_path):
    """The real thing: a detached process (no child of this one), at low priority, compiles
    the kernels into the object cache and removes its lock; one line said so."""
    import io
    import time
    from lagrange_gen.jit import native_background
    mod = generated("cart_pendulum")
    _tiered(monkeypatch, tmp_path)
    folder = portable.native_dir()
    kernels = [native.native_kernel(mod, name, folder) for name in ("forward_dynamics", "energy")]
    stream = io.StringIO()
    pid = native_background.compile_later(mod, kernels, folder, stream=stream)
    assert pid and "compiling 2 kernels of cart_pendulum at LLVM level 1 in the background" \
        in stream.getvalue() and stream.getvalue().count("\n") == 1
    lock = native_background.lock_path(mod, folder)
    deadline = time.time() + 120
    while lock.exists() and time.time() < deadline:
        time.sleep(0.2)
    assert not lock.exists()
    monkeypatch.setattr(native, "_KERNELS", {})
    for name in ("forward_dynamics", "energy"):
        kernel = native.native_kernel(mod, name, folder)
        assert (kernel.level, kernel.cached) == (1, True), name


def test_the_glue_background_process_compiles_kernels_at_the_default_level(monkeypatch, tmp_path):
    """jit.first_run's background process (the glue of a method's first use, with the model's
    kernel table) has no one waiting: no level-0 first tier there, no process of its own for
    level 1; the environment is given back as it was."""
    from lagrange_gen.jit import first_run
    monkeypatch.delenv(native.OPT_ENV, raising=False)
    monkeypatch.setattr(first_run.os, "nice", lambda increment: 0)
    seen = []
    monkeypatch.setattr(first_run, "compile_for_next_time",
                        lambda *args, **kwargs: seen.append((os.environ.get(native.OPT_ENV),
                                                             native.tiers_allowed(1))))
    first_run.main(["rk4", "m", "f", str(tmp_path / "lock")])
    assert seen == [(str(native.OPT_LEVEL), False)]
    assert native.OPT_ENV not in os.environ
