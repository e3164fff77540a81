"""The first-use notice: a glue call that outlasts compile_notice.NOTICE_AFTER_S prints one line
on stderr naming the glue and the model; a quick call (a cache hit) prints nothing."""

import re
import time
from types import SimpleNamespace

import numpy as np
import pytest

from lagrange_gen.jit import compile_notice
from lagrange_gen.run.adaptive_driver import _warm_up
from lagrange_gen.run.fixed_driver import warm_up, warm_up_args

LINE = re.compile(r"^lagrange-gen: compiling (\S+) for (\S+) \(first use\) \.\.\. "
                  r"(done in|failed after) (\d+\.\d) s\n$")


def _glue(seconds, error=None):
    """A stand-in for a generated run_<method>: takes any arguments, sleeps, maybe raises."""
    def run(*args):
        time.sleep(seconds)
        if error:
            raise error
        return 0, 0, 0
    return run


def _fixed_warm_up(run):
    q = np.zeros(2)
    args = warm_up_args(q, q, 0.0, 1e-3, np.ones(5), (), np.zeros((1, 0)), np.empty(7),
                        np.zeros((0, 7)))
    glue, seconds = warm_up(lambda: run, args, label="run_rattle for four_bar")
    assert glue is run
    return seconds


def test_slow_fixed_step_first_call_prints_one_line(monkeypatch, capsys):
    monkeypatch.setattr(compile_notice, "NOTICE_AFTER_S", 0.0)
    seconds = _fixed_warm_up(_glue(0.3))
    err = capsys.readouterr().err
    match = LINE.match(err)
    assert match, repr(err)
    assert match.group(1, 2, 3) == ("run_rattle", "four_bar", "done in")
    assert float(match.group(4)) == pytest.approx(seconds, abs=0.06)


def test_fast_call_prints_nothing(capsys):
    assert compile_notice.NOTICE_AFTER_S == 1.0
    _fixed_warm_up(_glue(0.0))
    time.sleep(0.05)            # a timer that was not cancelled would have no reason to wait
    assert capsys.readouterr().err == ""


def test_adaptive_first_call_names_method_and_model(monkeypatch, capsys):
    monkeypatch.setattr(compile_notice, "NOTICE_AFTER_S", 0.0)
    task = SimpleNamespace(glue=lambda args: _glue(0.2), t0=0.0, p=np.ones(5), settings=(), method="dop853",
                           module=SimpleNamespace(NAME="cart_pendulum"))
    _warm_up(task, np.zeros(2), np.zeros(2), np.zeros(0), np.empty(7), np.zeros((0, 7)))
    match = LINE.match(capsys.readouterr().err)
    assert match and match.group(1, 2, 3) == ("run_dop853", "cart_pendulum", "done in")


def test_failing_slow_call_ends_its_line_and_raises(monkeypatch, capsys):
    monkeypatch.setattr(compile_notice, "NOTICE_AFTER_S", 0.0)
    with pytest.raises(TypeError, match="bad types"):
        _fixed_warm_up(_glue(0.2, TypeError("bad types")))
    match = LINE.match(capsys.readouterr().err)
    assert match and match.group(3) == "failed after"
