"""lagrange_gen.jit.compile_gc: while numba compiles a lagrange_gen function, the young GC
threshold is raised; after the outermost compile, failed ones included, the thresholds are what
they were."""

import gc

import pytest
from numba.core import event

from lagrange_gen.jit import compile_gc, speedups
from lagrange_gen.jit.cache import njit


class _Seen(event.Listener):
    """Records gc.get_threshold() at every numba:compile start."""

    def __init__(self):
        self.thresholds = []

    def on_start(self, ev):
        self.thresholds.append(gc.get_threshold())

    def on_end(self, ev):
        pass


def _compile_with_listener(fn, *args):
    seen = _Seen()
    event.register("numba:compile", seen)
    try:
        return seen, fn(*args)
    finally:
        event.unregister("numba:compile", seen)


def test_the_threshold_is_raised_during_a_compile_and_restored_after():
    @njit
    def callee(x):
        return x + 1.0

    @njit
    def caller(x):
        return callee(x) * 2.0

    assert speedups.enabled("compile_gc")
    before = gc.get_threshold()
    seen, result = _compile_with_listener(caller, 1.5)
    assert result == 5.0
    assert len(seen.thresholds) >= 2                      # caller, and callee inside it
    assert all(t[0] == max(compile_gc.COMPILE_THRESHOLD, before[0]) and t[1:] == before[1:]
               for t in seen.thresholds)
    assert gc.get_threshold() == before


def test_a_failed_compile_restores_the_thresholds():
    @njit
    def broken(x):
        return x.no_such_attribute

    before = gc.get_threshold()
    with pytest.raises(Exception, match="no_such_attribute"):
        broken(1.0)
    assert gc.get_threshold() == before


def test_nested_scopes_set_and_restore_once():
    before = gc.get_threshold()
    try:
        with speedups.compiling():
            with speedups.compiling():
                assert gc.get_threshold()[0] == max(compile_gc.COMPILE_THRESHOLD, before[0])
            assert gc.get_threshold()[0] == max(compile_gc.COMPILE_THRESHOLD, before[0])
        assert gc.get_threshold() == before
    finally:
        gc.set_threshold(*before)
