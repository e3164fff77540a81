"""Atomic, change-only writing of generated files."""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

from ..errors import GenerationError


def write_if_changed(path, text: str) -> bool:
    """Write ``text`` to ``path`` atomically (temp file + os.replace) unless it is already there.

    Returns True when the file was (re)written. On any failure the previous file is untouched and
    no temporary file is left behind.
    """
    path = Path(path)
    try:
        if path.is_file() and path.read_text() == text:
            return False
    except (OSError, UnicodeDecodeError):
        pass
    directory = path.parent
    try:
        directory.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=directory)
    except OSError as exc:
        raise GenerationError(f"{directory}: cannot write generated files here ({exc.strerror})") from None
    try:
        with os.fdopen(fd, "w") as fh:
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
