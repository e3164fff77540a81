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
library version at a time: a lock file beside the portable glue (jit/background.py: the
detached process, the lock records, stale locks taken over). The next process then finds the glue in numba's cache (the warm path, unchanged). A
controlled run that compiled its specialized loop because the portable controlled glue was not
cached asks for that glue the same way (argument ``controlled``; its own lock).
$LAGRANGE_GEN_BACKGROUND_COMPILE=0 turns it off (tests and CI do); $LAGRANGE_GEN_INTERPRETED=0
turns the interpreted tier off. Both read the words of jit.env.env_flag.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from .background import (BACKGROUND_ENV, LOCK_STALE_S, background_enabled,  # noqa: F401 (tests read them here)
                         background_env, lock_held, lock_record, process_start, release_lock,
                         spawn_detached, take_lock, write_record)
from .env import env_flag

#: Environment variable that turns the interpreted tier off: a first run compiles in the
#: foreground, as before it existed (the test suite does, so that which code ran does not depend
#: on the order in which tests fill numba's cache; tests/test_interpreted.py turns it on).
INTERPRETED_ENV = "LAGRANGE_GEN_INTERPRETED"

#: CPU seconds a compile of a method's portable glue is expected to take before one was measured
#: on this machine: the first use of the lighter methods (rk4) takes 4 to 5 s on a loaded
#: two-core machine, the implicit ones 10 to 25 s.
DEFAULT_COMPILE_S = 10.0

#: The file of the recorded compile seconds, in the portable directory.
ESTIMATES_FILE = "compile_seconds.json"


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
    write_record(lock, pid)
    stream = stream or sys.stderr
    took_over = "".join(f"; {note}" for note in notes)
    glue = f"run_{method}_controlled" if controlled else f"run_{method}"
    stream.write(f"lagrange-gen: compiling {glue} in the background for the next run "
                 f"(process {pid}; {BACKGROUND_ENV}=0 turns this off{took_over})\n")
    stream.flush()
    return pid


def compile_running(method) -> bool:
    """Whether a live compile of ``method``'s portable glue holds its lock (another process, or
    the background compile this one started): a caller waits for it rather than compiling the
    same glue beside it (twice the memory, half the speed on two cores)."""
    lock = lock_path(method)
    return lock_held(lock)


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
    from .native import OPT_ENV, OPT_LEVEL
    method, name, path, lock = argv[:4]
    level_given = OPT_ENV in os.environ
    try:
        try:
            os.nice(10)
        except (AttributeError, OSError):      # no os.nice (Windows), or not allowed
            pass
        # no one waits here: the model's kernels at LLVM's default level at once, not level 0
        # first with yet another process for the better level (jit/native_background.py)
        if not level_given:
            os.environ[OPT_ENV] = str(OPT_LEVEL)
        compile_for_next_time(method, name, path, controlled=argv[4:] == ["controlled"])
    finally:
        if not level_given:
            os.environ.pop(OPT_ENV, None)
        release_lock(Path(lock))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
