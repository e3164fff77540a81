"""The switches (lagrange_gen.jit.env) and the lock of the background compile
(lagrange_gen.jit.first_run).

The boolean environment variables take the documented words (1/0, on/off, yes/no, true/false, in
any case); anything else is one warning line naming the variable and the value, then the default.
A lock records its process's pid, host and start time: a lock of junk (not a record, empty, a
bare pid) or of a process that is gone, or whose pid now belongs to another process, is stale
and taken over at once, with a note; a live compile's lock holds."""

import json
import os
import socket
import subprocess
import warnings

import pytest

from lagrange_gen.jit import env, first_run, native


@pytest.mark.parametrize("variable", [first_run.BACKGROUND_ENV, first_run.INTERPRETED_ENV])
@pytest.mark.parametrize("value, expected", [
    ("1", True), ("on", True), ("Yes", True), ("TRUE", True), (" true ", True),
    ("0", False), ("off", False), ("No", False), ("FALSE", False)])
def test_the_documented_words_are_read_silently(variable, value, expected, monkeypatch):
    monkeypatch.setenv(variable, value)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert env.env_flag(variable, default=not expected) is expected


@pytest.mark.parametrize("variable, read", [
    (first_run.BACKGROUND_ENV, first_run.background_enabled),
    (first_run.INTERPRETED_ENV, first_run.interpreted_enabled),
    (native.NATIVE_ENV, native.enabled)])
@pytest.mark.parametrize("value", ["maybe", "2", "of", "nope", ""])
def test_junk_is_one_warning_line_and_the_default(variable, read, value, monkeypatch):
    monkeypatch.setenv(variable, value)
    monkeypatch.setattr(env, "_WARNED", set())
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert read() is True                              # the default of each: on
        assert read() is True
    messages = [str(w.message) for w in caught]
    if value == "":
        assert messages == []                              # unset in effect: the default
        return
    assert len(messages) == 1 and "\n" not in messages[0]
    assert variable in messages[0] and repr(value) in messages[0]


def test_an_unset_variable_is_the_default(monkeypatch):
    monkeypatch.delenv(first_run.BACKGROUND_ENV, raising=False)
    assert env.env_flag(first_run.BACKGROUND_ENV, default=True) is True
    assert env.env_flag(first_run.BACKGROUND_ENV, default=False) is False


def _start_ticks(pid):
    return first_run.process_start(pid)


@pytest.fixture
def lock(tmp_path):
    return tmp_path / ".run_rk4.compiling"


@pytest.mark.parametrize("content", ["not-a-pid", "", "   \n", "12 34", "{\"pid\": \"x\"}", "[1]",
                                     "{\"pid\": -5}", "{\"pid\": 100000000000000000000}"])
def test_a_lock_of_junk_is_taken_over_at_once(lock, content):
    lock.write_text(content)
    notes = []
    assert first_run.take_lock(lock, notes)
    assert json.loads(lock.read_text())["pid"] == os.getpid()
    assert len(notes) == 1 and "stale" in notes[0] and "\n" not in notes[0]


def test_a_bare_pid_of_a_live_unrelated_process_is_taken_over(lock):
    """What the lock held before it was a record: the pid alone, which a live process that is no
    compile can hold (pid 1 always lives)."""
    lock.write_text("1")
    assert first_run.take_lock(lock)


@pytest.mark.skipif(first_run.process_start(os.getpid()) is None,
                    reason="no process start times here (/proc)")
def test_a_live_pid_started_after_its_lock_is_another_process(lock):
    """The pid is alive, but the process that has it now is not the one that wrote the lock:
    its start time differs."""
    record = first_run.lock_record(os.getpid())
    record["start"] += 1
    lock.write_text(json.dumps(record))
    notes = []
    assert first_run.take_lock(lock, notes)
    assert "another process" in notes[0]


def test_a_live_compile_holds_its_lock(lock):
    lock.write_text(json.dumps(first_run.lock_record(os.getpid())))
    before = lock.read_text()
    assert not first_run.take_lock(lock)
    assert lock.read_text() == before


def test_a_lock_of_a_process_that_is_gone_is_taken_over(lock):
    child = subprocess.Popen(["true"])
    child.wait()                                          # gone, its pid not yet reused
    lock.write_text(json.dumps(first_run.lock_record(child.pid) | {"start": 1}))
    notes = []
    assert first_run.take_lock(lock, notes)
    assert "gone" in notes[0] or "another process" in notes[0]


def test_another_hosts_lock_holds_until_it_is_old(lock):
    """Its pid means nothing here (a shared file system): only its age counts."""
    record = first_run.lock_record(os.getpid()) | {"host": socket.gethostname() + "-other"}
    lock.write_text(json.dumps(record))
    assert not first_run.take_lock(lock)
    old = os.stat(lock).st_mtime - first_run.LOCK_STALE_S - 10
    os.utime(lock, (old, old))
    assert first_run.take_lock(lock)


def test_a_new_lock_is_never_seen_empty(lock, monkeypatch):
    """The record is in the lock from the moment it exists (written, then linked in)."""
    seen = []
    real_link = os.link

    def link(src, dst, *args, **kwargs):
        seen.append(open(src).read())
        return real_link(src, dst, *args, **kwargs)

    monkeypatch.setattr(os, "link", link)
    assert first_run.take_lock(lock)
    assert seen and json.loads(seen[0])["pid"] == os.getpid()
    assert not [p for p in lock.parent.iterdir() if p != lock]      # no temporary left
