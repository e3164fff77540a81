"""The jit layer: every contact with numba's compiler and cache.

njit with a cache keyed on a function's source closure (cache), the compile without numba's
wrappers for functions only jitted code calls (callee), numba speedups (inline_copy,
typing_memo, compile_gc; which are on, and the scope they patch in: speedups), the compile
notice (compile_notice) and the portable glue that runs one compiled stepper on any model's
kernel table (portable). Imports numba lazily. Its core (everything but portable, specialized,
first_run and interpreted, which bind the steppers to a module's kernels) imports nothing of the
steppers or the generator (docs/ARCHITECTURE.md, "Which folder may import which").

Importing it checks numba's version against speedups.SUPPORTED_NUMBA (an older numba: one-line
ImportError; a newer one: one warning, speedups off).
"""

from .speedups import check_numba_version as _check_numba_version

_check_numba_version()

from .cache import CALLEE_MODULES, closure_stamp, compiled_for_jitted_callers, njit  # noqa: E402

#: numba options of a function that never allocates: no reference counting (every call from a
#: stepper would pay for it).
NO_REFCOUNT = {"_nrt": False}

#: numba options of every generated kernel (``@njit(**KERNEL_OPTIONS)``): cached; no reference
#: counting; numpy's error model, so a division by zero gives inf/NaN, which the steppers report
#: as NON_FINITE, instead of raising inside the jitted loop.
KERNEL_OPTIONS = dict(cache=True, **NO_REFCOUNT, error_model="numpy")

__all__ = ["njit", "closure_stamp", "compiled_for_jitted_callers", "CALLEE_MODULES",
           "KERNEL_OPTIONS", "NO_REFCOUNT", "check_python_calls"]


def __getattr__(name):
    """check_python_calls, imported on first use: it needs numpy, which the freshness check of a
    generated module (codegen.keys, through jit.sources) does not (``lagrange-gen`` on an
    unchanged model imports neither)."""
    if name == "check_python_calls":
        from .python_calls import check_python_calls
        return check_python_calls
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
