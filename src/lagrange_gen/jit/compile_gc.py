"""Python's cyclic garbage collector runs rarely while numba compiles.

A numba compile allocates millions of container objects (IR nodes, type maps, LLVM wrappers),
most of which stay alive until the function is compiled. CPython's collector runs a young
collection every 700 net allocations and traverses every object of the young generation each
time, and the survivors again in the older generations: profiled (perf, cart pendulum, first
simulate of verlet with empty caches) the collector's functions (gc_collect_main, visit_decref,
visit_reachable, ...) took about 10 % of the compile. Measured the same way (midpoint, three
runs each, new processes): 7.28 / 7.56 / 7.50 s with the default thresholds, 6.99 / 7.06 /
6.67 s with the young threshold at 200000 during the compile (peak RSS 297 -> 314 MB), 7.53 /
7.08 / 6.75 s with the collector off (359 MB).

``install()`` (lagrange_gen.jit.njit calls it) registers a numba event listener that sets the
young generation's threshold to COMPILE_THRESHOLD when the outermost numba compile of the
process starts (numba:compile, which a cache load is too) and restores the thresholds it found
when that compile ends, failed compiles included. The thresholds are the process's, so other
threads allocate under them meanwhile. Nothing else changes: the collector stays enabled and
collects as usual, only less often. With the listener installed the cart pendulum's midpoint
took 6.61 / 7.08 / 6.97 s against 7.00 / 7.37 / 7.42 s with $LAGRANGE_GEN_COMPILE_GC=0, which
leaves the thresholds alone.
"""

from __future__ import annotations

import gc
import os
import threading

from numba.core import event

#: Environment variable: "0" leaves the collector's thresholds as they are.
ENV = "LAGRANGE_GEN_COMPILE_GC"

#: The young generation's threshold while numba compiles (CPython's default is 700).
COMPILE_THRESHOLD = 200_000

_listener = None
_install_lock = threading.Lock()


class CompileGcListener(event.Listener):
    """numba:compile listener raising the young GC threshold during the outermost compile.
    Compiles nest (a callee compiles inside its caller's compile) and numba compiles one
    function at a time per process (its global compiler lock); the depth is counted under a
    lock all the same, so that the thresholds are set and restored once."""

    def __init__(self):
        self._lock = threading.Lock()
        self._depth = 0
        self._saved = None

    def on_start(self, ev):
        with self._lock:
            self._depth += 1
            if self._depth == 1:
                self._saved = gc.get_threshold()
                gc.set_threshold(max(COMPILE_THRESHOLD, self._saved[0]), *self._saved[1:])

    def on_end(self, ev):
        with self._lock:
            self._depth -= 1
            if self._depth == 0 and self._saved is not None:
                gc.set_threshold(*self._saved)
                self._saved = None


def install():
    """Register the listener once per process (not when $LAGRANGE_GEN_COMPILE_GC is "0");
    returns whether it is registered."""
    global _listener
    with _install_lock:
        if _listener is None and os.environ.get(ENV) != "0":
            _listener = CompileGcListener()
            event.register("numba:compile", _listener)
    return _listener is not None
