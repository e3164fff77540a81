"""The package's own source files: which ones a module is compiled from, and their hashes.

Compiled code of the package is built from more files than the one that defines it: numba
compiles every function a jitted function calls into it. Two things key on that set of files,
the source closure of a module (source_closure):

- a generated module's KEY and SOURCES (codegen.generate), so a changed stepper regenerates it;
- numba's on-disk cache of the package's own ``cache=True`` functions (lagrange_gen.jit), so a
  changed callee recompiles its cached callers.

Light on purpose (no sympy, no numba): lagrange_gen.jit, which every jitted module of the
package imports, imports it too (the closure itself is read at a function's first cache load or
save).
"""

from __future__ import annotations

import ast
import hashlib
import json
from functools import lru_cache
from pathlib import Path

_PACKAGE = Path(__file__).resolve().parents[1]     # src/lagrange_gen


def relative_module(dotted, level, module):
    """Dotted name (relative to lagrange_gen) that ``from <level dots><module> import`` inside
    the module ``dotted`` refers to."""
    parts = dotted.split(".")[:-level] if level <= dotted.count(".") + 1 else []
    if module:
        parts += module.split(".")
    return ".".join(parts)


def module_path(dotted):
    """File of a package module given relative to lagrange_gen (None if not a module file)."""
    path = _PACKAGE.joinpath(*dotted.split(".")) if dotted else _PACKAGE
    if path.with_suffix(".py").is_file():
        return path.with_suffix(".py")
    if (path / "__init__.py").is_file():
        return path / "__init__.py"
    return None


def module_name(path) -> str | None:
    """Dotted name relative to lagrange_gen of the package file ``path`` (None outside it)."""
    try:
        relative = Path(path).resolve().relative_to(_PACKAGE)
    except ValueError:
        return None
    parts = list(relative.with_suffix("").parts)
    if parts and parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def source_closure(roots) -> tuple:
    """Package files (paths relative to lagrange_gen, sorted) of the modules ``roots`` (dotted,
    relative to lagrange_gen: "steppers.rattle", "linalg") and of every package module they
    import, transitively, at any level of the file (a function-level import counts too).

    This is what compiled code of a generated module is built from, so what its KEY hashes.
    Package ``__init__`` files are not followed: they run at import, numba compiles nothing
    from them."""
    seen, files, todo = set(), [], list(roots)
    known, changed = _import_memo(), False
    while todo:
        dotted = todo.pop()
        path = module_path(dotted)
        if dotted in seen or path is None or path.name == "__init__.py":
            continue
        seen.add(dotted)
        relative = path.relative_to(_PACKAGE).as_posix()
        files.append(relative)
        stat = path.stat()
        digest = _file_hash(str(path), stat.st_mtime_ns, stat.st_size)
        if known.get(relative, (None,))[0] != digest:
            known[relative] = (digest, list(_imports_of(dotted, str(path), stat.st_mtime_ns, stat.st_size)))
            changed = True
        todo += known[relative][1]
    if changed:
        _save_import_memo(known)
    return tuple(sorted(files))


#: The import graph of the package files, by file and content hash: {relative path: (sha256
#: prefix, imported modules)}, kept on disk (IMPORT_MEMO_FILE in the portable folder) so that a
#: new process reads it instead of parsing every file its glue compiles from.
_IMPORT_MEMO = {"entries": None}

#: File name of the import graph's memo in the portable folder.
IMPORT_MEMO_FILE = "imports.json"


def _import_memo() -> dict:
    """The import graph's memo, read from disk once per process ({} when missing or unreadable:
    every file is parsed)."""
    if _IMPORT_MEMO["entries"] is None:
        entries = {}
        try:
            from .folders import portable_dir
            raw = json.loads((portable_dir() / IMPORT_MEMO_FILE).read_text())
            entries = {str(k): (str(v[0]), [str(m) for m in v[1]]) for k, v in raw.items()}
        except (OSError, ValueError, TypeError, IndexError, AttributeError):
            pass
        _IMPORT_MEMO["entries"] = entries
    return _IMPORT_MEMO["entries"]


def _save_import_memo(entries):
    """Write the memo atomically; a folder that cannot be written keeps none (a memo only)."""
    try:
        from .folders import portable_dir, write_atomic
        write_atomic(portable_dir() / IMPORT_MEMO_FILE, json.dumps(entries, sort_keys=True).encode())
    except OSError:
        pass


@lru_cache(maxsize=None)
def _imports_of(dotted, path, mtime_ns, size):
    """imported_modules of one file, parsed once per version of it (mtime and size are part of
    the memo key: a file edited while we run is parsed again)."""
    return tuple(imported_modules(dotted, ast.parse(Path(path).read_text(), path)))


def imported_modules(dotted, tree):
    """Dotted names (relative to lagrange_gen) of the package modules ``tree`` imports."""
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = relative_module(dotted, node.level, node.module)
            elif (node.module or "").split(".")[0] == _PACKAGE.name:
                base = node.module.partition(".")[2]
            else:
                continue
            found.append(base)
            found += [f"{base}.{a.name}" if base else a.name for a in node.names]
        elif isinstance(node, ast.Import):
            found += [a.name.partition(".")[2] for a in node.names if a.name.split(".")[0] == _PACKAGE.name]
    return [name for name in found if name and module_path(name) is not None]


def source_hashes(files) -> dict:
    """{path relative to lagrange_gen: sha256 of its bytes (16 hex digits), or "missing"}."""
    hashes = {}
    for name in files:
        path = _PACKAGE / name
        if path.is_file():
            stat = path.stat()
            hashes[name] = _file_hash(str(path), stat.st_mtime_ns, stat.st_size)
        else:
            hashes[name] = "missing"
    return hashes


@lru_cache(maxsize=None)
def _file_hash(path, mtime_ns, size):
    """sha256 prefix of one file, read once per version of it (as _imports_of)."""
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()[:16]
