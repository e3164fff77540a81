"""Atomic, change-only writing of generated files.

A file is written to ``.<name>.<pid>.tmp`` next to its target and renamed over it, so a reader
never sees half a module. A writer killed between the two (SIGKILL, power loss) leaves its temp
file behind; the next write of the same target removes the temp files of processes that no
longer exist. The written file gets the mode an ordinary ``open`` would give it (0666 minus the
umask), or keeps the mode of the file it replaces.
"""

from __future__ import annotations

import os
import stat
import threading
from pathlib import Path

from ..errors import GenerationError

# One writer per process at a time: the temp name carries only the pid.
_WRITING = threading.Lock()


def write_if_changed(path, text: str) -> bool:
    """Write ``text`` to ``path`` atomically (temp file + os.replace) unless it is already there.

    Returns True when the file was (re)written. On any failure the previous file is untouched and
    no temporary file is left behind.
    """
    path = Path(path)
    try:
        if path.is_file() and path.read_text(encoding="utf-8") == text:
            return False
    except (OSError, UnicodeDecodeError):
        pass
    directory = path.parent
    with _WRITING:
        try:
            directory.mkdir(parents=True, exist_ok=True)
            _remove_dead_writers_temp_files(path)
            tmp, fd = _create_temp(path)
        except OSError as exc:
            raise GenerationError(f"{directory}: cannot write generated files here "
                                  f"({exc.strerror}); choose another folder with -o DIR "
                                  f"(lagrange-gen) or out_dir= (lagrange_gen.load, simulate, "
                                  f"ensemble)") from None
        try:
            with os.fdopen(fd, "w", encoding="utf-8", newline="\n") as fh:
                fh.write(text)
            os.replace(tmp, path)
        except BaseException as exc:
            try:
                os.unlink(tmp)
            except OSError:
                pass
            if isinstance(exc, OSError):
                raise GenerationError(f"{path}: cannot write ({exc.strerror})") from None
            raise
    return True


def _temp_name(path, pid) -> Path:
    return path.parent / f".{path.name}.{pid}.tmp"


def _create_temp(path):
    """(temp path, open fd) for writing ``path``: created with mode 0666 & ~umask like any new
    file, or given the mode of the existing ``path``."""
    tmp = _temp_name(path, os.getpid())
    flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL
    try:
        fd = os.open(tmp, flags, 0o666)
    except FileExistsError:        # left by a dead process that had our pid (we hold _WRITING)
        os.unlink(tmp)
        fd = os.open(tmp, flags, 0o666)
    try:
        mode = stat.S_IMODE(os.stat(path).st_mode)
    except FileNotFoundError:
        return tmp, fd
    try:
        os.chmod(tmp, mode)
    except BaseException:
        os.close(fd)
        os.unlink(tmp)
        raise
    return tmp, fd


def _remove_dead_writers_temp_files(path):
    """Remove ``.<name>.<pid>.tmp`` files of ``path`` whose writing process no longer exists."""
    prefix, me = f".{path.name}.", os.getpid()
    for entry in path.parent.iterdir():
        pid = entry.name[len(prefix):-len(".tmp")]
        if not (entry.name.startswith(prefix) and entry.name.endswith(".tmp") and pid.isdigit()):
            continue
        if int(pid) != me and not _process_exists(int(pid)):
            try:
                entry.unlink()
            except OSError:
                pass


def _process_exists(pid) -> bool:
    """Whether process ``pid`` exists on this machine (True when that cannot be told)."""
    if os.name != "posix":
        return True            # os.kill would terminate it on Windows: never guess
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:
        return True            # exists, owned by another user
    return True
