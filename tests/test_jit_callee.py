"""lagrange_gen.jit.callee: the stepper library's uncached functions are compiled without numba's
CPython and cfunc wrappers. A jitted caller must get the same code, a call from Python must work
(numba alone would jump to a missing entry point: a segmentation fault), and the cached
functions, which numba loads through their wrapper, must keep it."""

import functools
import importlib
import json
import os
import pkgutil
import subprocess
import sys

import numpy as np
from numba.core.registry import CPUDispatcher

from lg_test_support import ROOT
from lagrange_gen import steppers
from lagrange_gen.jit.cache import njit
from lagrange_gen.jit.callee import CalleeDispatcher
from lagrange_gen.steppers.core import linalg


def _library_dispatchers():
    """Every numba dispatcher defined in lagrange_gen.steppers.* (linalg included)."""
    modules = [importlib.import_module(info.name) for info in
               pkgutil.walk_packages(steppers.__path__, "lagrange_gen.steppers.")]
    assert linalg in modules
    for module in modules:
        for value in vars(module).values():
            if isinstance(value, CPUDispatcher) and value.py_func.__module__ == module.__name__:
                yield value


def test_uncached_library_functions_have_no_wrappers_and_cached_ones_keep_them():
    callees = cached = 0
    for dispatcher in _library_dispatchers():
        name = f"{dispatcher.py_func.__module__}.{dispatcher.py_func.__qualname__}"
        if dispatcher._cache.__class__.__name__ == "NullCache":
            assert type(dispatcher) is CalleeDispatcher, name
            assert dispatcher.targetoptions["no_cpython_wrapper"] is True, name
            assert dispatcher.targetoptions["no_cfunc_wrapper"] is True, name
            callees += 1
        else:
            assert type(dispatcher) is not CalleeDispatcher, name
            assert not dispatcher.targetoptions.get("no_cpython_wrapper"), name
            cached += 1
    # the steps, Newton solves, workspaces and loops of every method; linalg's kernels
    assert callees > 100 and cached > 20, (callees, cached)


@njit
def _solve_in_jitted_code(A, piv, b, n):
    ok = linalg.cholesky_inplace(A)
    linalg.cholesky_as_lu(A, piv, n)            # a CalleeDispatcher, called from jitted code
    linalg.lu_solve_inplace(A, piv, b, np.zeros(n))
    return ok


def test_a_call_from_python_runs_a_twin_with_wrappers_and_the_same_result():
    assert type(linalg.cholesky_as_lu) is CalleeDispatcher
    rng = np.random.default_rng(3)
    M = rng.normal(size=(4, 4))
    A, b = M @ M.T + 4 * np.eye(4), rng.normal(size=4)
    A1, piv1, b1 = A.copy(), np.zeros(4, np.int64), b.copy()
    assert _solve_in_jitted_code(A1, piv1, b1, 4)
    A2, piv2 = A.copy(), np.zeros(4, np.int64)
    assert linalg.cholesky_inplace(A2)
    linalg.cholesky_as_lu(A2, piv2, 4)               # from Python: compiles the twin
    linalg.lu_solve_inplace(A2, piv2, b2 := b.copy(), np.zeros(4))
    np.testing.assert_array_equal(A1, A2)
    np.testing.assert_array_equal(b1, b2)
    np.testing.assert_allclose(b1, np.linalg.solve(A, b), rtol=1e-12)
    twin = linalg.cholesky_as_lu.python_twin()
    assert type(twin) is CPUDispatcher and twin.py_func is linalg.cholesky_as_lu.py_func
    assert not twin.targetoptions.get("no_cpython_wrapper")
    assert linalg.cholesky_as_lu.python_twin() is twin          # compiled once


# A first simulate in a fresh process with empty numba and portable caches; prints the class of
# midpoint's step (to show which compile ran), the final state's bits, and the signatures
# output.save_row was compiled for.
_RUN = """
import json, os, sys, tempfile
os.environ["NUMBA_CACHE_DIR"] = tempfile.mkdtemp()
os.environ["LAGRANGE_GEN_PORTABLE_DIR"] = tempfile.mkdtemp()
from lagrange_gen.run.loader import import_generated
from lagrange_gen.run.simulate import simulate
from lagrange_gen.steppers.core import output
from lagrange_gen.steppers.methods import midpoint
mod = import_generated(os.path.join(sys.argv[1], "generated", "cart_pendulum.py"))
tr = simulate(mod, "midpoint", [0.1, 1.0], [0.3, -0.2], t_end=0.2, h=1e-2)
print(json.dumps([type(midpoint.step).__name__, [x.hex() for x in tr.q[-1]],
                  [x.hex() for x in tr.v[-1]], [str(sig) for sig in output.save_row.signatures]]))
"""


@functools.lru_cache(maxsize=None)
def _run(wrappers):
    env = dict(os.environ, LAGRANGE_GEN_SPEEDUPS="-callee" if wrappers else "all")
    done = subprocess.run([sys.executable, "-c", _RUN, str(ROOT)], capture_output=True,
                          text=True, env=env, timeout=600)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout.strip().splitlines()[-1])


def test_a_stepper_compiled_without_wrappers_gives_the_same_bits():
    without, with_wrappers = _run(False), _run(True)
    assert without[0] == "CalleeDispatcher" and with_wrappers[0] == "CPUDispatcher"
    assert without[1:3] == with_wrappers[1:3]


def test_the_run_loop_compiles_one_save_per_glue():
    """output.save_row is compiled separately (cached); run_loop's calls must agree on its argument
    types, or each first compile of a glue pays for a second one (a literal row 0 did)."""
    signatures = _run(False)[3]
    assert len(signatures) == 1, signatures
