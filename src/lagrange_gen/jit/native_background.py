"""Big native kernels at LLVM's default level, compiled by a background process for the next run.

A kernel's object code at LLVM's level 1 is what every later run loads (jit/native.py), but on a
big model its code generation is most of the wait before the first step (the 30-DoF humanoid's
implicit-Euler kernels: seconds at level 1, a fraction at level 0). So a kernel with more IR
than native.FAST_FIRST_BYTES whose level-1 object is not cached yet runs at level 0 in the run
that needs it (two to three times the time per call, the same numbers), and ``compile_later``
starts one detached process, at low priority, that compiles those kernels at level 1 into the
object cache, with one line on stderr:

    lagrange-gen: compiling 3 kernels of humanoid at LLVM level 1 in the background for the next run (dynamics, mass_matvec_dq, rhs_jacobian; process 4242; LAGRANGE_GEN_BACKGROUND_COMPILE=0 turns this off)

The next process finds them. One such process per generated module text at a time (a lock
file in the object cache, jit.background's lock records); with background compiles off
($LAGRANGE_GEN_BACKGROUND_COMPILE=0), or an explicit $LAGRANGE_GEN_NATIVE_OPT, every kernel is
compiled at its level in the foreground, as before.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

from .background import (BACKGROUND_ENV, background_enabled, background_env, release_lock,
                         spawn_detached, take_lock, write_record)


def lock_path(module, folder: Path) -> Path:
    """The lock of the background compile of ``module``'s kernels, in the object cache."""
    return Path(folder) / f".kernels_{str(getattr(module, 'TEXT_SHA', ''))[:16] or module.__name__}.compiling"


def compile_later(module, kernels, folder: Path, stream=None):
    """Start the background compile of the ``kernels`` (NativeKernels of ``module``) that run
    below the level they want, unless there are none, background compiles are off or another
    process holds the module's lock. Returns the process id, or None."""
    pending = sorted({k.name for k in kernels if getattr(k, "level", 0) < getattr(k, "wanted", 0)})
    if not pending or not background_enabled():
        return None
    level = max(k.wanted for k in kernels if k.name in pending)
    lock = lock_path(module, folder)
    notes = []
    if not take_lock(lock, notes):
        return None
    try:
        pid = spawn_detached([sys.executable, "-m", __name__, module.__name__, module.__file__,
                              str(folder), str(level), str(lock), *pending], background_env())
    except (OSError, ValueError, subprocess.SubprocessError):
        release_lock(lock)
        return None
    write_record(lock, pid)
    took_over = "".join(f"; {note}" for note in notes)
    model = getattr(module, "NAME", None) or str(module.__name__).rsplit(".", 1)[-1]
    stream = stream or sys.stderr
    stream.write(f"lagrange-gen: compiling {len(pending)} kernel{'s' * (len(pending) > 1)} of "
                 f"{model} at LLVM level {level} in the background for the next run "
                 f"({', '.join(pending)}; process {pid}; {BACKGROUND_ENV}=0 turns this off"
                 f"{took_over})\n")
    stream.flush()
    return pid


def compile_kernels(name, path, folder: Path, level: int, kernels) -> None:
    """In the background process: import the generated module at ``path`` as ``name`` and
    compile each kernel of ``kernels`` at ``level`` into the object cache ``folder`` (nothing
    for one already there)."""
    from . import native
    from .folders import import_file
    from .native_ir import Unsupported
    module = import_file(name, Path(path))
    for kernel in kernels:
        try:
            native.native_kernel(module, kernel, Path(folder), level=level)
        except Unsupported:          # the foreground run said so already
            pass


def main(argv) -> int:
    name, path, folder, level, lock, *kernels = argv
    try:
        try:
            os.nice(10)
        except (AttributeError, OSError):      # no os.nice (Windows), or not allowed
            pass
        compile_kernels(name, path, Path(folder), int(level), kernels)
    finally:
        release_lock(Path(lock))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
