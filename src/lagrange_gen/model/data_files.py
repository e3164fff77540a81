"""The files a model file reads while it runs (its parameters from a JSON file, a table of
coefficients, a Python file it exec()s): recorded at generation, so that a changed one makes the
generated module stale for load, simulate, generation and a direct import, as it is for
``lagrange-gen --check`` (codegen.generated_files records them; codegen.keys.changed_input
decides for all of them).

Files are seen through Python's audit hook "open" (sys.addaudithook, installed once on first
use, recording only inside ``files_read``): whatever opens them (open, Path.read_text, numpy's
loaders), as long as it goes through Python's open. Recorded: regular files opened for reading,
Python source too (a file exec()d as data), but not the model file itself, bytecode and
extension modules, nor files of the Python installation, of installed packages or of
lagrange-gen itself (its sources are the generator's, keys.generator_hash). The modules a model
file imports that are not installed (a helper beside it, or in a folder it put on sys.path) are
recorded beside these by model/model_file.py, with the same rule (is_model_input).
"""

from __future__ import annotations

import hashlib
import os
import sys
import threading
from contextlib import contextmanager
from pathlib import Path

__all__ = ["files_read", "file_record", "is_model_input"]

_STATE = threading.local()
_HOOK_INSTALLED = False
_NOT_INPUT_SUFFIXES = (".pyc", ".pyo", ".pyd", ".so", ".pth")
_PACKAGE = os.path.realpath(Path(__file__).resolve().parents[1])       # src/lagrange_gen


@contextmanager
def files_read(exclude=()):
    """Within the block, collect the absolute paths of the data files opened for reading by
    this thread (a set, yielded; filled when the block ends). ``exclude``: paths not to record."""
    _install_hook()
    found = set()
    outer = getattr(_STATE, "found", None)
    _STATE.found = found
    try:
        yield found
    finally:
        _STATE.found = outer
        skip = {os.path.realpath(p) for p in exclude}
        kept = {p for p in found if p not in skip and is_model_input(p)}
        found.clear()
        found.update(kept)
        if outer is not None:
            outer.update(kept)


def file_record(path) -> dict:
    """{"sha256", "size", "mtime_ns"} of a file now; {} when it cannot be read (then any later
    state of it counts as a change)."""
    try:
        stat = os.stat(path)
        return {"sha256": _sha256(path), "size": stat.st_size, "mtime_ns": stat.st_mtime_ns}
    except OSError:
        return {}


def _sha256(path):
    digest = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def _install_hook():
    global _HOOK_INSTALLED
    if not _HOOK_INSTALLED:
        _HOOK_INSTALLED = True
        sys.addaudithook(_audit)


def _audit(event, args):
    """The audit hook: record a file opened for reading while files_read is active."""
    if event != "open":
        return
    found = getattr(_STATE, "found", None)
    if found is None or not args:
        return
    path, mode = args[0], args[1] if len(args) > 1 else None
    flags = args[2] if len(args) > 2 else 0
    if isinstance(path, int) or path is None:
        return
    if isinstance(mode, str):
        if any(c in mode for c in "wax") and "+" not in mode:
            return
    elif isinstance(flags, int) and flags & (os.O_WRONLY | os.O_RDWR) == os.O_WRONLY:
        return
    try:
        found.add(os.path.realpath(os.fsdecode(path)))
    except (TypeError, ValueError):
        pass


def is_model_input(path) -> bool:
    """True when the file at the real path ``path`` is the model's own input: a regular file
    that is not bytecode or an extension module, and not part of the Python installation, an
    installed package (site-packages, dist-packages) or lagrange-gen."""
    if not os.path.isfile(path) or path.endswith(_NOT_INPUT_SUFFIXES):
        return False
    parts = Path(path).parts
    if "site-packages" in parts or "dist-packages" in parts or "__pycache__" in parts:
        return False
    roots = {os.path.realpath(p) for p in (sys.prefix, sys.base_prefix, sys.exec_prefix)} | {_PACKAGE}
    return not any(path.startswith(root + os.sep) for root in roots)
