"""numba's public names the runtime uses beside ``njit``: typing a value, a class compiled with
its methods, a structure passed by reference (structref: unlike a jitclass, its type can be
cached on disk), an overload of a Python helper inside jitted code, the parallel range and the
thread counts. Importing them from here keeps every contact with numba in jit/, so a numba
release that moves one of them is answered in this file alone. Imports numba.
"""

from __future__ import annotations

import numba
from numba import get_num_threads, prange, set_num_threads, typeof, types
from numba.experimental import jitclass, structref
from numba.extending import overload

__all__ = ["get_num_threads", "set_num_threads", "max_threads", "jitclass", "overload", "prange", "structref",
           "typeof", "types"]


def max_threads() -> int:
    """The most threads a parallel loop may use in this process (NUMBA_NUM_THREADS)."""
    return numba.config.NUMBA_NUM_THREADS
