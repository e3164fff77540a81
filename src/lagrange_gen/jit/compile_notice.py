"""Tell the user when a first call compiles for more than a second.

The first call of a generated run_<method> compiles it with numba (seconds) or loads it from
numba's cache (a fraction of a second). A silent pause of 10 s looks like a hang, so
:func:`first_use_notice` starts a timer around that call: if the call is still running after
NOTICE_AFTER_S, one line appears on stderr,
``lagrange-gen: compiling run_rattle for four_bar (first use) ...``, completed by
`` done in 7.9 s`` when the call returns. A call that returns sooner (a cache hit) prints
nothing.
"""

from __future__ import annotations

import sys
import threading
import time
from contextlib import contextmanager

#: Seconds a first call may take before the notice appears (tests set it to 0).
NOTICE_AFTER_S = 1.0


@contextmanager
def first_use_notice(label, stream=None):
    """Context manager around a call that may compile ``label`` (e.g. "run_rattle for
    four_bar"); prints the notice on ``stream`` (default sys.stderr) only if the call outlasts
    NOTICE_AFTER_S."""
    stream = stream or sys.stderr
    lock, state = threading.Lock(), {"returned": False, "shown": False}
    start = time.perf_counter()

    def announce():
        with lock:
            if not state["returned"]:
                stream.write(f"lagrange-gen: compiling {label} (first use) ...")
                stream.flush()
                state["shown"] = True

    timer = threading.Timer(NOTICE_AFTER_S, announce)
    timer.daemon = True
    timer.start()
    outcome = "failed after"
    try:
        yield
        outcome = "done in"
    finally:
        timer.cancel()
        # The lock orders the two threads: either the notice was written completely before
        # this point (then finish its line), or it never will be.
        with lock:
            state["returned"] = True
            if state["shown"]:
                stream.write(f" {outcome} {time.perf_counter() - start:.1f} s\n")
                stream.flush()
