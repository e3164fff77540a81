"""The jit layer: every contact with numba's compiler and cache.

njit with a cache keyed on a function's source closure (cache), the compile without numba's
wrappers for functions only jitted code calls (callee), numba speedups (inline_copy,
typing_memo, compile_gc), the compile notice (compile_notice) and the portable glue that runs
one compiled stepper on any model's kernel table (portable). Imports numba lazily; may import
codegen.keys / codegen.sources and the stepper runtime, never sympy, derive or the codegen
pipeline.
"""

from .cache import CALLEE_MODULES, WRAPPERS_ENV, closure_stamp, compiled_for_jitted_callers, njit

__all__ = ["njit", "closure_stamp", "compiled_for_jitted_callers", "CALLEE_MODULES", "WRAPPERS_ENV"]
