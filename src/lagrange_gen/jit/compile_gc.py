"""Python's cyclic garbage collector runs rarely while numba compiles.

A numba compile allocates millions of container objects (IR nodes, type maps, LLVM wrappers),
most of which stay alive until the function is compiled. CPython's collector runs a young
collection every 700 net allocations and traverses every object of the young generation each
time, and the survivors again in the older generations: in a profile (perf, cart pendulum, first
simulate of verlet with empty caches) the collector's functions (gc_collect_main, visit_decref,
visit_reachable, ...) take about 10 % of the compile. A young threshold of COMPILE_THRESHOLD
during the compile saves about as much as turning the collector off, for a small fraction of
the peak memory that costs (compile time with and without: ``lagrange-gen bench compile``,
reports/compile.md).

``activate()`` sets the young generation's threshold to COMPILE_THRESHOLD when the outermost
compile of a lagrange_gen function starts (jit.speedups.compiling, cache loads included) and
its undo restores the thresholds it found when that compile ends, failed compiles included.
The thresholds are the process's, but numba's compiler lock is held meanwhile. Nothing else
changes: the collector stays enabled and collects as usual, only less often.
$LAGRANGE_GEN_SPEEDUPS without compile_gc leaves the thresholds alone. It touches no numba
internals.
"""

from __future__ import annotations

import gc

#: The young generation's threshold while numba compiles (CPython's default is 700).
COMPILE_THRESHOLD = 200_000


def unsupported():
    """None: the speedup touches only the gc module."""
    return None


def activate():
    """Raise the young generation's threshold; returns the undo."""
    saved = gc.get_threshold()
    gc.set_threshold(max(COMPILE_THRESHOLD, saved[0]), *saved[1:])

    def restore():
        gc.set_threshold(*saved)

    return restore
