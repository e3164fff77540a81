"""The first run of a method after an install: what a compile is expected to cost, and the
compile done in a background process for the next one.

A run that starts in the interpreted tier (jit/interpreted.py, chosen by run/fixed_driver.py)
compiles nothing in the foreground unless its remaining interpreted time would pass the compile
it saves; ``expected_compile_seconds`` is that compile: the CPU seconds of the last compile of the
method's portable glue (with a model's kernels) recorded in the portable directory
(``record_compile_seconds``), else DEFAULT_COMPILE_S.

Meanwhile ``start_background_compile`` fills numba's cache for the next process: a detached
process at low priority, ``python -m lagrange_gen.jit.first_run <method> <module name> <module
file> <lock>``, imports the generated module under the same name (numba's cache refers to it by
name), compiles its kernels for the portable glue and the portable glue with a zero-step call of
the argument types simulate passes, and records its CPU seconds. One process per method and
library version at a time: a lock file beside the portable glue records the compiling process
(pid, host, start time: ``lock_record``); a stale lock (older than LOCK_STALE_S, of a process that
is gone or whose pid another process now has, or not a record at all) is taken over at once, with
a note. The next process then finds the glue in numba's cache (the warm path, unchanged). A
controlled run that compiled its specialized loop because the portable controlled glue was not
cached asks for that glue the same way (argument ``controlled``; its own lock).
$LAGRANGE_GEN_BACKGROUND_COMPILE=0 turns it off (tests and CI do); $LAGRANGE_GEN_INTERPRETED=0
turns the interpreted tier off. Both read the words of jit.env.env_flag.
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

#: Environment variable that turns the interpreted tier off: a first run compiles in the
#: foreground, as before it existed (the test suite does, so that which code ran does not depend
#: on the order in which tests fill numba's cache; tests/test_interpreted.py turns it on).
INTERPRETED_ENV = "LAGRANGE_GEN_INTERPRETED"

#: CPU seconds a compile of a method's portable glue is expected to take before one was measured
#: on this machine: the first use of the lighter methods (rk4) takes 4 to 5 s on a loaded
#: two-core machine, the implicit ones 10 to 25 s.
DEFAULT_COMPILE_S = 10.0

#: A lock file older than this (seconds) is taken to belong to a compile that died.
LOCK_STALE_S = 900.0

#: The file of the recorded compile seconds, in the portable directory.
ESTIMATES_FILE = "compile_seconds.json"


def background_enabled() -> bool:
    """Whether a background compile may start ($LAGRANGE_GEN_BACKGROUND_COMPILE)."""
    return env_flag(BACKGROUND_ENV, True)


def interpreted_enabled() -> bool:
    """Whether a first run may start interpreted ($LAGRANGE_GEN_INTERPRETED)."""
    return env_flag(INTERPRETED_ENV, True)


def _estimates_path() -> Path:
    from .folders import portable_dir
    return portable_dir() / ESTIMATES_FILE


def expected_compile_seconds(method) -> float:
    """CPU seconds the compile of ``method``'s portable glue is expected to take."""
    try:
        value = json.loads(_estimates_path().read_text()).get(method)
        return float(value) if value and float(value) > 0 else DEFAULT_COMPILE_S
    except (OSError, ValueError, AttributeError, TypeError):
        return DEFAULT_COMPILE_S


def record_compile_seconds(method, seconds) -> None:
    """Record that a compile of ``method``'s portable glue took ``seconds`` (CPU); written
    atomically, a failure to write is ignored (the default stands)."""
    path = _estimates_path()
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        try:
            known = json.loads(path.read_text())
            if not isinstance(known, dict):
                known = {}
        except (OSError, ValueError):
            known = {}
        known[method] = round(float(seconds), 3)
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=".compile_seconds.", suffix=".tmp")
        with os.fdopen(fd, "w") as f:
            json.dump(known, f, sort_keys=True)
        os.replace(tmp, path)
    except OSError:
        pass


def lock_path(method, controlled=False) -> Path:
    """The lock file of a background compile of ``method``'s portable glue (controlled: its
    controlled glue), beside the glue."""
    from .portable import glue_path
    path = glue_path(method)
    return path.with_name(f".{path.stem}{'_controlled' if controlled else ''}.compiling")


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


def _write_record(lock: Path, pid) -> None:
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


def release_lock(lock: Path) -> None:
    try:
        lock.unlink()
    except OSError:
        pass


def start_background_compile(module, method, stream=None, controlled=False):
    """Start the detached compile of ``method``'s portable glue (controlled: the portable
    controlled glue, portable.controlled_runner) and ``module``'s kernels for the next process
    (module docstring) unless it is turned off or another holds the lock; one line on
    ``stream`` (default stderr) says so. Returns the process id, or None."""
    if not background_enabled():
        return None
    lock = lock_path(method, controlled)
    notes = []
    if not take_lock(lock, notes):
        return None
    try:
        pid = spawn_detached(
            [sys.executable, "-m", __name__, method, module.__name__, module.__file__, str(lock)]
            + (["controlled"] if controlled else []), background_env())
    except (OSError, ValueError, subprocess.SubprocessError):
        release_lock(lock)
        return None
    _write_record(lock, pid)
    stream = stream or sys.stderr
    took_over = "".join(f"; {note}" for note in notes)
    glue = f"run_{method}_controlled" if controlled else f"run_{method}"
    stream.write(f"lagrange-gen: compiling {glue} in the background for the next run "
                 f"(process {pid}; {BACKGROUND_ENV}=0 turns this off{took_over})\n")
    stream.flush()
    return pid


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


def compile_running(method) -> bool:
    """Whether a live compile of ``method``'s portable glue holds its lock (another process, or
    the background compile this one started): a caller waits for it rather than compiling the
    same glue beside it (twice the memory, half the speed on two cores)."""
    lock = lock_path(method)
    return lock.exists() and _stale(lock) is None


def zero_step_args(module, method):
    """The portable glue's arguments of a zero-step run of ``method`` on ``module`` of the types
    simulate passes (run/fixed_driver.py's warm-up): fresh writable float64 arrays, the
    method's default settings record."""
    import numpy as np
    from ..steppers.core.layout import N_STATS, events_size, last_size
    from ..steppers.core.registry import spec
    from .portable import n_saved
    n, saved = module.N_COORDS, n_saved(module, method)
    p = np.array(module.DEFAULT_PARAMS, dtype=np.float64)
    return (np.zeros(n), np.zeros(n), 0.0, 1e-3, 0, 1, p, spec(method).settings(),
            np.empty(1), np.empty((1, n)), np.empty((1, n)), np.empty((1, N_STATS)),
            np.zeros((1, saved)), np.zeros(last_size(n, saved, with_work=True)),
            np.zeros((0, events_size(n))))


def compile_for_next_time(method, name, path, controlled=False) -> float:
    """In the background process: import the generated module at ``path`` as ``name``, compile
    its kernels and the portable glue of ``method`` (nothing when numba's cache has it), record
    the CPU seconds. controlled: the portable controlled glue instead, with a hook that writes
    nothing (portable.no_inputs_hook: its type is every hook's), seconds not recorded (the
    estimate is the uncontrolled glue's). Returns the seconds (0 when nothing was compiled)."""
    import importlib.util
    import numpy as np
    from .portable import controlled_runner, no_inputs_hook, portable_cached, runner
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    if portable_cached(module, method, controlled):
        return 0.0
    start = time.process_time()
    if controlled:
        controlled_runner(module, method, no_inputs_hook(), np.zeros(0))(
            *zero_step_args(module, method))
        return time.process_time() - start
    runner(module, method)(*zero_step_args(module, method))
    seconds = time.process_time() - start
    record_compile_seconds(method, seconds)
    return seconds


def main(argv) -> int:
    method, name, path, lock = argv[:4]
    try:
        try:
            os.nice(10)
        except (AttributeError, OSError):      # no os.nice (Windows), or not allowed
            pass
        compile_for_next_time(method, name, path, controlled=argv[4:] == ["controlled"])
    finally:
        release_lock(Path(lock))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
