"""The first-use notice: a glue call in which numba compiles and that outlasts
compile_notice.NOTICE_AFTER_S prints one line on stderr naming the glue and the model; a call
that compiles nothing (a warm call, a cache hit, a slow call without a compile) prints nothing
and starts no thread."""

import re
import threading
import time
from types import SimpleNamespace

import numba
import numpy as np
import pytest

from lagrange_gen.jit import compile_notice
from lagrange_gen.run.adaptive_driver import _warm_up
from lagrange_gen.run.fixed_driver import warm_up, warm_up_args

LINE = re.compile(r"^lagrange-gen: compiling (\S+) for (\S+) \(first use\) \.\.\. "
                  r"(done in|failed after) (\d+\.\d) s\n$")


def _compiling_glue(error=False):
    """A stand-in for a generated run_<method>: takes any arguments and calls a function numba
    compiles on its first call (a new one per stand-in, never cached); with error, one whose
    typing fails."""
    if error:
        @numba.njit
        def work(x):
            return x + "a string"
    else:
        @numba.njit
        def work(x):
            return x + 1.0

    def run(*args):
        work(1.0)
        return 0, 0, 0
    return run


def _sleeping_glue(seconds):
    def run(*args):
        time.sleep(seconds)
        return 0, 0, 0
    return run


def _fixed_warm_up(run):
    q = np.zeros(2)
    args = warm_up_args(q, q, 0.0, 1e-3, np.ones(5), (), np.zeros((1, 0)), np.empty(7),
                        np.zeros((0, 7)))
    glue, seconds = warm_up(lambda: run, args, label="run_rattle for four_bar")
    assert glue is run
    return seconds


def test_compiling_first_call_prints_one_line(monkeypatch, capsys):
    monkeypatch.setattr(compile_notice, "NOTICE_AFTER_S", 0.0)
    before = compile_notice.compiles()
    seconds = _fixed_warm_up(_compiling_glue())
    assert compile_notice.compiles() > before
    err = capsys.readouterr().err
    match = LINE.match(err)
    assert match, repr(err)
    assert match.group(1, 2, 3) == ("run_rattle", "four_bar", "done in")
    assert float(match.group(4)) == pytest.approx(seconds, abs=0.06)


def test_warm_call_prints_nothing_and_starts_no_thread(monkeypatch, capsys):
    monkeypatch.setattr(compile_notice, "NOTICE_AFTER_S", 0.0)
    run = _compiling_glue()
    _fixed_warm_up(run)
    capsys.readouterr()
    started = []
    monkeypatch.setattr(threading.Timer, "start", lambda self: started.append(self))
    before = compile_notice.compiles()
    _fixed_warm_up(run)                 # everything compiled: nothing to say
    assert started == []
    assert compile_notice.compiles() == before
    assert capsys.readouterr().err == ""


def test_slow_call_without_a_compile_prints_nothing(monkeypatch, capsys):
    monkeypatch.setattr(compile_notice, "NOTICE_AFTER_S", 0.0)
    _fixed_warm_up(_sleeping_glue(0.2))
    time.sleep(0.05)
    assert capsys.readouterr().err == ""


def test_default_threshold_is_a_second(capsys):
    assert compile_notice.NOTICE_AFTER_S == 1.0
    _fixed_warm_up(_compiling_glue())       # a compile well under a second
    time.sleep(0.05)            # a timer that was not cancelled would have no reason to wait
    assert capsys.readouterr().err == ""


def test_adaptive_first_call_names_method_and_model(monkeypatch, capsys):
    monkeypatch.setattr(compile_notice, "NOTICE_AFTER_S", 0.0)
    run = _compiling_glue()
    task = SimpleNamespace(glue=lambda args: run, t0=0.0, p=np.ones(5), settings=(),
                           method="dop853", module=SimpleNamespace(NAME="cart_pendulum"))
    _warm_up(task, np.zeros(2), np.zeros(2), np.zeros(0), np.empty(7), np.zeros((0, 7)))
    match = LINE.match(capsys.readouterr().err)
    assert match and match.group(1, 2, 3) == ("run_dop853", "cart_pendulum", "done in")


def test_failing_compile_ends_its_line_and_raises(monkeypatch, capsys):
    monkeypatch.setattr(compile_notice, "NOTICE_AFTER_S", 0.0)
    with pytest.raises(numba.core.errors.TypingError):
        _fixed_warm_up(_compiling_glue(error=True))
    match = LINE.match(capsys.readouterr().err)
    assert match and match.group(3) == "failed after"


def test_nested_notice_names_the_inner_call(monkeypatch, capsys):
    monkeypatch.setattr(compile_notice, "NOTICE_AFTER_S", 0.0)
    run = _compiling_glue()
    with compile_notice.first_use_notice("run_verlet for outer"):
        with compile_notice.first_use_notice("run_verlet for inner"):
            run()
    match = LINE.match(capsys.readouterr().err)
    assert match and match.group(2) == "inner"


def test_layout_sizes_from_python_compile_nothing():
    """The sizes simulate computes from Python in every new process (out_last, out_events)
    come from the layout functions' Python bodies: a new process compiles nothing for them
    (a jitted helper called from Python would compile a twin each time, a second or so)."""
    import subprocess
    import sys
    code = ("from numba.core import event\n"
            "seen = []\n"
            "class L(event.Listener):\n"
            "    def on_start(self, ev): seen.append(ev.data['dispatcher'])\n"
            "    def on_end(self, ev): pass\n"
            "event.register('numba:compile', L())\n"
            "import numpy as np\n"
            "from lagrange_gen.steppers.core.layout import events_size, last_size, read_last\n"
            "last = np.zeros(last_size(3, 2, with_work=True))\n"
            "read_last(last, 3, with_work=True)\n"
            "assert last.shape == (1 + 6 + 2 + 2 + 1,) and events_size(3) == 9\n"
            "print(len(seen))\n")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["0"]


def test_a_line_written_while_the_notice_is_open_gets_a_line_of_its_own(monkeypatch, capsys):
    """A warning written while a call compiles (an unreadable cache entry found by a callee's
    compile) ends the notice's line first; the notice then ends on a line naming the glue again
    (before, the warning was glued to "... (first use) ..." and " done in" stood alone)."""
    import sys
    monkeypatch.setattr(compile_notice, "NOTICE_AFTER_S", 0.0)
    work = _compiling_glue()

    def run(*args):
        deadline = time.perf_counter() + 5.0
        work()                                  # compiles: the notice's timer starts
        while time.perf_counter() < deadline and not compile_notice._OPEN.notice.shown:
            time.sleep(0.01)
        compile_notice.end_open_lines()
        sys.stderr.write("lagrange-gen: warning: something while compiling\n")
        return 0, 0, 0

    _fixed_warm_up(run)
    lines = capsys.readouterr().err.splitlines()
    assert lines[0] == "lagrange-gen: compiling run_rattle for four_bar (first use) ...", lines
    assert lines[1] == "lagrange-gen: warning: something while compiling", lines
    assert re.fullmatch(r"lagrange-gen: compiling run_rattle for four_bar done in \d+\.\d s",
                        lines[2]), lines
    assert len(lines) == 3, lines
