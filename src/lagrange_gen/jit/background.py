"""Processes that compile in the background for the next run, and their lock files.

A compile that would make a user wait (the portable glue of a method's first use,
jit/first_run.py; the big native kernels at LLVM's better level, jit/native_background.py) is
done by a detached process at low priority (``spawn_detached``: not a child of the user's
process, which therefore exits without "subprocess N is still running"). One such process per
thing compiled at a time: a lock file records the compiling process (pid, host, start time:
``lock_record``); a stale lock (older than LOCK_STALE_S, of a process that is gone or whose pid
another process now has, or not a record at all) is taken over at once, with a note.
$LAGRANGE_GEN_BACKGROUND_COMPILE=0 turns every background compile off (tests and CI do); it reads
the words of jit.env.env_flag.
"""

from __future__ import annotations

import json
import os
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from .env import env_flag

#: Environment variable that turns the background compile off ("0", "off", "no" or "false").
BACKGROUND_ENV = "LAGRANGE_GEN_BACKGROUND_COMPILE"

#: A lock file older than this (seconds) is taken to belong to a compile that died.
LOCK_STALE_S = 900.0

def background_enabled() -> bool:
    """Whether a background compile may start ($LAGRANGE_GEN_BACKGROUND_COMPILE)."""
    return env_flag(BACKGROUND_ENV, True)


def process_start(pid):
    """When process ``pid`` started, in clock ticks since boot (/proc/<pid>/stat, field 22):
    what tells a process from a later one with the same pid. None where it cannot be read (no
    such process, no /proc)."""
    try:
        with open(f"/proc/{int(pid)}/stat", "rb") as f:
            fields = f.read().rsplit(b")", 1)[1].split()
        return int(fields[19])        # field 22; fields[0] is field 3 (the state)
    except (OSError, ValueError, IndexError):
        return None


def lock_record(pid) -> dict:
    """What a lock holds: the pid, host and start time (process_start) of the compiling
    process."""
    return {"pid": int(pid), "host": socket.gethostname(), "start": process_start(pid)}


def take_lock(lock: Path, notes=None) -> bool:
    """Create ``lock`` holding this process's record (False when a live compile holds it, or
    when the directory cannot be written); a stale one (_stale) is taken over, and the reason
    appended to ``notes`` (a list) when given."""
    record = json.dumps(lock_record(os.getpid()))
    for _ in range(3):
        try:
            if _create(lock, record):
                return True
        except OSError:          # a directory we may not write: no background compile
            return False
        reason = _stale(lock)
        if reason is None:
            return False
        try:
            lock.unlink()
        except FileNotFoundError:
            pass
        except OSError:
            return False
        if notes is not None and reason:
            notes.append(f"took over the stale lock {lock} ({reason})")
    return False


def _create(lock: Path, text: str) -> bool:
    """Create ``lock`` holding ``text``, False when it exists: the text is written to a
    temporary file first and linked in, so that no process ever reads the lock empty (where the
    file system has no hard links: created exclusively, then written)."""
    fd, tmp = tempfile.mkstemp(dir=lock.parent, prefix=f"{lock.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "w") as f:
            f.write(text)
        try:
            os.link(tmp, lock)
            return True
        except FileExistsError:
            return False
        except OSError:
            pass
        try:
            fd = os.open(lock, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o644)
        except FileExistsError:
            return False
        with os.fdopen(fd, "w") as f:
            f.write(text)
        return True
    finally:
        try:
            os.unlink(tmp)
        except OSError:
            pass


def write_record(lock: Path, pid) -> None:
    """Replace the record in ``lock`` by that of process ``pid`` (atomically: never empty)."""
    fd, tmp = tempfile.mkstemp(dir=lock.parent, prefix=f"{lock.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "w") as f:
            json.dump(lock_record(pid), f)
        os.replace(tmp, lock)
    except OSError:
        try:
            os.unlink(tmp)
        except OSError:
            pass


def _stale(lock: Path):
    """Why ``lock`` is stale (a short phrase; "" when it is gone already), or None while a live
    compile may hold it: older than LOCK_STALE_S; not a lock record (junk, empty, the bare pid
    of older versions); on this host, a process that is gone, or a live pid whose start time is
    not the recorded one (another process got the pid). Another host's lock: its age only."""
    try:
        age = time.time() - lock.stat().st_mtime
        text = lock.read_text()
    except FileNotFoundError:
        return ""
    except OSError:
        return None
    if age > LOCK_STALE_S:
        return f"{age / 60:.0f} minutes old"
    try:
        record = json.loads(text)
        pid = record["pid"]
        if isinstance(pid, bool) or not isinstance(pid, int) or not 0 < pid < 2**31:
            raise TypeError
    except (ValueError, TypeError, KeyError):
        return f"not a lock record: {text.strip()[:40]!r}"
    if record.get("host") != socket.gethostname() or os.name == "nt":
        return None              # (Windows' os.kill would end the process): age only
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return f"process {pid} is gone"
    except OSError:              # alive, another user's
        pass
    start, recorded = process_start(pid), record.get("start")
    if start is not None and recorded is not None and start != recorded:
        return f"process {pid} is another process now"
    return None


def lock_held(lock: Path) -> bool:
    """Whether a live process holds ``lock`` (it exists and is not stale)."""
    return lock.exists() and _stale(lock) is None


def release_lock(lock: Path) -> None:
    try:
        lock.unlink()
    except OSError:
        pass


def background_env() -> dict:
    """This process's environment with this package's parent first on PYTHONPATH: a background
    process runs the same lagrange_gen as the one that started it."""
    package_parent = str(Path(__file__).resolve().parents[2])
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(
        [package_parent] + [p for p in env.get("PYTHONPATH", "").split(os.pathsep) if p])
    return env


#: The launcher of a detached process: it forks, the child starts a session of its own and
#: becomes the command, the launcher prints the child's pid and exits.
_LAUNCHER = (
    "import os, sys\n"
    "pid = os.fork()\n"
    "if pid == 0:\n"
    "    os.setsid()\n"
    "    null = os.open(os.devnull, os.O_RDWR)\n"
    "    for fd in (0, 1, 2):\n"
    "        os.dup2(null, fd)\n"
    "    os.execv(sys.argv[1], sys.argv[1:])\n"
    "print(pid, flush=True)\n")


def spawn_detached(argv, env) -> int:
    """Start ``argv`` as a process of its own session, not a child of this one, and return its
    pid. The launcher in between is waited for, so this process never exits with a child still
    running (Python's "subprocess N is still running" at exit) and the compile outlives it.
    Where there is no fork (Windows): a detached child."""
    if not hasattr(os, "fork"):
        process = subprocess.Popen(argv, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                                   stderr=subprocess.DEVNULL, env=env, close_fds=True,
                                   creationflags=getattr(subprocess, "DETACHED_PROCESS", 0))
        process.returncode = 0        # not ours to wait for: it outlives this process
        return process.pid
    launcher = subprocess.run([sys.executable, "-c", _LAUNCHER, *argv], env=env,
                              stdin=subprocess.DEVNULL, capture_output=True, text=True,
                              timeout=60, check=True)
    return int(launcher.stdout.split()[0])
