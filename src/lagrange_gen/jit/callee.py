"""Dispatchers of the stepper library compiled without numba's CPython and C wrappers.

For every function it compiles, numba also compiles two wrappers: one that unboxes Python
arguments so the function can be called from Python (the "CPython wrapper"), and one with a C
calling convention so it can be passed as a first-class function value (the "cfunc wrapper").
The functions of the stepper library (lagrange_gen.steppers.*, lagrange_gen.steppers.core.linalg) are called
by jitted code only: the glue (a generated module's ``run_<method>``, the portable glue, the step
API's loops) compiles them in, each one that is not inlined at numba-IR level as a function of
its own (numba's typing of a call compiles the callee). Their wrappers are never used, and they
cost compile time in every first compile of a stepper: dropping them takes a sixth to a quarter off
a first simulate with empty caches (with and without: ``lagrange-gen bench compile``,
reports/compile.md). The compiled steps are the same: tests/test_jit_callee.py compares a run's bits
with and without ($LAGRANGE_GEN_SPEEDUPS=-callee keeps the wrappers, jit.speedups).

numba itself gives a function compiled without the CPython wrapper no safe Python entry: calling it
from Python jumps to an entry point that does not exist (a segmentation fault, measured). A
CalleeDispatcher therefore answers a call from Python by compiling, on the first such call, a twin
with the wrappers (the same Python function and options) and calling that: the function works from
Python as any dispatcher does, at the cost of one more compile, paid only by whoever calls it from
Python (tests, a debugging session).
"""

from __future__ import annotations

import numba
from numba.core.registry import CPUDispatcher

#: numba target options that drop the two wrappers.
NO_WRAPPERS = dict(no_cpython_wrapper=True, no_cfunc_wrapper=True)


def unsupported():
    """None when numba's CPU target takes the NO_WRAPPERS options, else why not."""
    options = CPUDispatcher.targetdescr.options
    missing = [name for name in NO_WRAPPERS if not hasattr(options, name)]
    if missing:
        return f"numba's CPU target options lack {', '.join(missing)}"
    return None


class CalleeDispatcher(CPUDispatcher):
    """numba's CPU dispatcher of a function compiled for jitted callers only (module docstring):
    a jitted caller uses it as any dispatcher; a call from Python runs ``python_twin``."""

    def __call__(self, *args, **kwargs):
        return self.python_twin()(*args, **kwargs)

    def python_twin(self):
        """numba's own dispatcher of the same function and options, wrappers included (compiled
        on its first call)."""
        twin = self.__dict__.get("_python_twin")
        if twin is None:
            # (numba.njit sets nopython itself and warns when it is passed)
            options = {key: value for key, value in self.targetoptions.items()
                       if key not in NO_WRAPPERS and key != "nopython"}
            twin = numba.njit(locals=dict(self.locals), **options)(self.py_func)
            self._python_twin = twin
        return twin


def callee_dispatcher(fn, options):
    """``numba.njit(**options)(fn)`` without wrappers, as a CalleeDispatcher. ``options`` must
    not ask for ``cache``: numba loads a cached function through its CPython wrapper."""
    if options.get("cache"):
        raise ValueError(f"{fn.__qualname__}: a cached function keeps numba's wrappers")
    dispatcher = numba.njit(**options, **NO_WRAPPERS)(fn)
    if type(dispatcher) is CPUDispatcher:         # not the plain function of NUMBA_DISABLE_JIT
        dispatcher.__class__ = CalleeDispatcher  # same layout: CalleeDispatcher adds no state
    return dispatcher
