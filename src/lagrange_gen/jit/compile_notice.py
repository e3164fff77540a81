"""Tell the user when a call compiles for more than a second.

The first call of a generated run_<method> compiles it with numba (seconds) or loads it from
numba's cache (a fraction of a second). A silent pause of 10 s looks like a hang, so
:func:`first_use_notice` watches such a call: when numba starts compiling inside it (numba's
``numba:compile`` event, which a cache hit does not fire) a timer is started, and if the call is
still running NOTICE_AFTER_S after it began, one line appears on stderr,
``lagrange-gen: compiling run_rattle for four_bar (first use) ...``, completed by
`` done in 7.9 s`` when the call returns. A call that compiles nothing (everything in memory or
in numba's cache) prints nothing and starts no thread, so the context costs about a microsecond
and may wrap every call.

``compiles()`` counts the compiles numba has started while any notice was open (tests check
with it that a warm call compiles nothing).
"""

from __future__ import annotations

import sys
import threading
import time

#: Seconds a call may take before the notice appears (tests set it to 0).
NOTICE_AFTER_S = 1.0

#: The notice open in each thread (the innermost one; it restores the one around it).
_OPEN = threading.local()
_COUNT = [0]
_LISTENING = []


def compiles() -> int:
    """How many numba compiles started inside a notice in this process so far."""
    return _COUNT[0]


def _listen():
    """Register, once per process, the listener of numba's compile events."""
    if _LISTENING:
        return
    from numba.core import event

    class CompileListener(event.Listener):
        def on_start(self, ev):
            notice = getattr(_OPEN, "notice", None)
            if notice is not None:
                _COUNT[0] += 1
                notice.compiling()

        def on_end(self, ev):
            pass

    event.register("numba:compile", CompileListener())
    _LISTENING.append(True)


def time_outermost_compiles(classify):
    """Register a listener that adds the seconds of each outermost numba compile (one that is
    not nested in another) to ``seconds[classify(module name of the compiled function)]``;
    returns that dict, filled as compiles end (what a first-run measurement reads)."""
    from numba.core import event
    seconds, open_compiles = {}, []

    class OutermostCompiles(event.Listener):
        def on_start(self, ev):
            open_compiles.append((time.perf_counter(), ev.data["dispatcher"]))

        def on_end(self, ev):
            start, dispatcher = open_compiles.pop()
            if not open_compiles:
                name = getattr(getattr(dispatcher, "py_func", None), "__module__", "") or ""
                kind = classify(name)
                seconds[kind] = seconds.get(kind, 0.0) + time.perf_counter() - start

    event.register("numba:compile", OutermostCompiles())
    return seconds


class first_use_notice:
    """Context manager around a call that may compile ``label`` (e.g. "run_rattle for
    four_bar"); prints the notice on ``stream`` (default sys.stderr) only if numba compiles
    inside it and the call outlasts NOTICE_AFTER_S."""

    __slots__ = ("label", "stream", "start", "lock", "timer", "shown", "returned", "around",
                 "broken")

    def __init__(self, label, stream=None):
        self.label, self.stream = label, stream
        self.timer, self.shown, self.returned, self.around = None, False, False, None
        self.broken = False

    def __enter__(self):
        if not _LISTENING:
            _listen()
        self.around = getattr(_OPEN, "notice", None)
        _OPEN.notice = self
        self.start = time.perf_counter()
        return self

    def compiling(self):
        """numba started a compile inside this call: start the timer once."""
        if self.timer is not None or self.returned:
            return
        self.lock = threading.Lock()
        wait = max(0.0, NOTICE_AFTER_S - (time.perf_counter() - self.start))
        self.timer = threading.Timer(wait, self._announce)
        self.timer.daemon = True
        self.timer.start()

    def _announce(self):
        with self.lock:
            if not self.returned:
                stream = self.stream or sys.stderr
                stream.write(f"lagrange-gen: compiling {self.label} (first use) ...")
                stream.flush()
                self.shown = True

    def end_line(self):
        """Another line is about to be written (a warning while this call compiles): end the
        notice's line now; its end is then a line of its own."""
        if self.timer is None:
            return
        with self.lock:
            if self.shown and not self.returned and not self.broken:
                stream = self.stream or sys.stderr
                stream.write("\n")
                stream.flush()
                self.broken = True

    def __exit__(self, kind, value, traceback):
        _OPEN.notice = self.around
        if self.timer is None:
            self.returned = True
            return False
        self.timer.cancel()
        # The lock orders the two threads: either the notice was written completely before
        # this point (then finish its line), or it never will be.
        with self.lock:
            self.returned = True
            if self.shown:
                stream = self.stream or sys.stderr
                outcome = "done in" if kind is None else "failed after"
                opening = f"lagrange-gen: compiling {self.label}" if self.broken else ""
                stream.write(f"{opening} {outcome} {time.perf_counter() - self.start:.1f} s\n")
                stream.flush()
        return False


def end_open_lines():
    """End the line of every notice shown in this thread and still open (first_use_notice.
    end_line): call before writing another line to stderr while a compile may be announced."""
    notice = getattr(_OPEN, "notice", None)
    while notice is not None:
        notice.end_line()
        notice = notice.around
