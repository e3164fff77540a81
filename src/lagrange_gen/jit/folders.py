"""Where the library keeps what it compiles: the portable folder and its library versions.

``portable_dir()`` holds the portable and specialized stepper glue (one directory per library
version, portable.library_hash), the native kernels' object code (``native/``), the compile
estimates and the background compile's locks (jit/first_run.py). A folder that cannot be written
is replaced, for the rest of the process, by a per-user temporary one (one warning line).
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

#: Environment variable naming the directory of the portable glue sources (default
#: ~/.cache/lagrange_gen/portable, or a per-user temporary directory when the home is not
#: writable, or when the directory cannot be written: portable_dir).
DIR_ENV = "LAGRANGE_GEN_PORTABLE_DIR"

#: A library version's glue directory (portable_dir()/<library hash>) not used for this many days
#: is removed when a new version's directory is made: every upgrade of lagrange-gen, and every
#: edit of a stepper in a checkout, writes a new one (a few MB of compiled glue each).
UNUSED_DAYS = 30


def portable_dir() -> Path:
    """Directory under which the portable glue sources are written: $LAGRANGE_GEN_PORTABLE_DIR,
    else ~/.cache/lagrange_gen/portable (a per-user temporary directory when the home is not
    writable); the per-user temporary directory instead once writing to that one failed in this
    process (_use_fallback_dir)."""
    configured = _configured_dir()
    return _FALLBACK_DIRS.get(configured, configured)


def _configured_dir() -> Path:
    if os.environ.get(DIR_ENV):
        return Path(os.environ[DIR_ENV])
    home = Path(os.path.expanduser("~"))
    if os.access(home, os.W_OK):
        return home / ".cache" / "lagrange_gen" / "portable"
    return _temporary_dir()


def _temporary_dir() -> Path:
    """The per-user temporary glue directory: another user's is neither written nor imported."""
    user = os.getuid() if hasattr(os, "getuid") else os.environ.get("USERNAME", "user")
    return Path(tempfile.gettempdir()) / f"lagrange_gen_portable-{user}"


#: {configured directory: the directory used instead}: a configured directory that could not be
#: written (a file, read-only, no space) is replaced for the rest of the process, so that the
#: glue, the compile estimates and the locks of jit.first_run stay together.
_FALLBACK_DIRS: dict = {}


def _use_fallback_dir(failed: Path, exc: OSError) -> Path:
    """Switch from ``failed`` (the configured directory, which could not be written: ``exc``) to
    the per-user temporary directory, with one warning line; SimulationError in one line when
    that cannot be used either (or is not this user's). Returns the new directory."""
    import warnings
    from ..errors import SimulationError
    configured = _configured_dir()
    fallback = _temporary_dir()
    why = exc.strerror or type(exc).__name__
    if fallback == configured or fallback == failed:
        raise SimulationError(f"cannot write the portable glue under {failed} ({why}); set "
                              f"{DIR_ENV} to a writable directory") from None
    try:
        fallback.mkdir(mode=0o700, parents=True, exist_ok=True)
        if hasattr(os, "getuid") and fallback.stat().st_uid != os.getuid():
            raise PermissionError(0, "owned by another user")
    except OSError as second:
        raise SimulationError(
            f"cannot write the portable glue under {failed} ({why}) nor under {fallback} "
            f"({second.strerror or type(second).__name__}); set {DIR_ENV} to a writable "
            f"directory") from None
    _FALLBACK_DIRS[configured] = fallback
    source = f"{DIR_ENV}={configured}" if os.environ.get(DIR_ENV) else str(configured)
    warnings.warn(f"lagrange-gen: {source} cannot be written ({why}); the portable glue and "
                  f"its compile records go to {fallback} instead", RuntimeWarning, stacklevel=4)
    return fallback


def native_dir() -> Path:
    """Where native kernels' object code is kept (jit/native.py): beside the portable glue."""
    return portable_dir() / "native"


def write_in_version(digest: str, name: str, source: str) -> Path:
    """The file ``name`` holding ``source`` in the library version ``digest``'s directory
    (write_versioned), replaced by the per-user temporary one when the configured directory
    cannot be written (_use_fallback_dir)."""
    try:
        return write_versioned(portable_dir() / digest, name, source)
    except OSError as exc:
        return write_versioned(_use_fallback_dir(portable_dir(), exc) / digest, name, source)


def write_versioned(folder: Path, name: str, source: str) -> Path:
    """The file ``name`` in ``folder`` (a library version's directory, or a folder below one),
    written atomically unless it already holds ``source``; OSError when it cannot be."""
    path = folder / name
    if not folder.is_dir():
        folder.mkdir(parents=True, exist_ok=True)
        remove_unused_versions(folder)
    try:
        os.utime(folder)               # marks the version used now (remove_unused_versions)
    except OSError:                    # a shared directory we may not touch: it is only a mark
        pass
    if not path.is_file() or path.read_text() != source:
        write_atomic(path, source.encode())
    return path


def remove_unused_versions(current: Path) -> list:
    """Remove the sibling library-version directories of ``current`` (16 hex digits, as
    library_hash names them; anything else is left alone) whose modification time, refreshed
    by every process that uses one (portable and specialized glue), is more than UNUSED_DAYS old. A process still
    loading from one loses only its cache: an unreadable entry is a miss (lagrange_gen.jit).
    Returns the directories removed."""
    import shutil
    import time
    cutoff = time.time() - UNUSED_DAYS * 86400
    removed = []
    for entry in current.parent.iterdir():
        name = entry.name
        if entry == current or len(name) != 16 or not all(c in "0123456789abcdef" for c in name):
            continue
        try:
            if entry.is_dir() and entry.stat().st_mtime < cutoff:
                shutil.rmtree(entry)
                removed.append(entry)
        except OSError:                # another process removed or is writing it: leave it
            pass
    return removed


def write_atomic(path: Path, data: bytes) -> None:
    """Write ``data`` to ``path`` through a temporary file in its folder (made if missing) and
    a rename: a reader sees the old file or the new one, never a part."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise


def import_file(name: str, path: Path):
    """The module ``name`` executed from the file ``path`` and registered in sys.modules under
    that name (numba's cache finds a module's globals by its name); nothing is left registered
    when its execution fails."""
    import importlib.util
    import sys
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    try:
        spec.loader.exec_module(module)
    except BaseException:
        del sys.modules[name]
        raise
    return module
