"""load()'s memory of the model files it has run: which generated module a model file gave, so
that loading the same file again finds its module without running the file (running a robot's
model file costs seconds: building its mechanics frames and bodies in sympy).

An entry is keyed by the content that decides what the file builds: its resolved path, its text,
the build options (``--set``) and the generator's sources (codegen.keys.generator_hash, which
covers model/, derive/, codegen/). It names the module the file gave. The module serves a later
load only when, read from disk without sympy: the module was generated from this file, its
derivation record (written by generation next to numba's cache) says it was generated from this
very text with this generator, its text and the package sources it compiles are unchanged
(keys.why_stale), and it has what is asked (methods, freeze, build options). Anything else -
no entry, a record with fields this check does not know, a missing method - goes the ordinary
way: run the file, re-derive if needed.

The data files the model file read when it was generated are in the record too (their sha256,
size and mtime): the module serves only while every one is unchanged (keys.changed_data_file,
which reads a file only when its size or mtime moved); so are the helper modules it imported
from its own folder (model/model_file.py).
"""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path

from ..codegen.keys import (changed_data_file, derivation_record_path, generator_hash, model_hash,
                           read_header, why_stale)

#: The fields of a derivation record this check compares (codegen.generated_files._record and the
#: data files' sizes and times that remember_current adds).
_RECORD_FIELDS = {"model", "data", "generator", "options", "key", "data_files"}


def entry_path(model_path, out_dir, options) -> Path:
    """Where the entry of a model file (with build ``options``) for ``out_dir`` is kept."""
    path = Path(model_path).resolve()
    h = hashlib.sha256(str(path).encode())
    h.update(b"\0" + path.read_bytes())
    h.update(b"\0" + json.dumps(dict(options or {}), sort_keys=True, default=str).encode())
    h.update(b"\0" + generator_hash().encode())
    return Path(out_dir) / "__pycache__" / f"model-{h.hexdigest()[:24]}.lagrange-gen-load.json"


def remember_module(model_path, out_dir, options, target):
    """Record that running ``model_path`` with ``options`` gave the module ``target``. Best
    effort: an unwritable directory only means the file is run next time."""
    try:
        path = entry_path(model_path, out_dir, options)
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_suffix(f".{os.getpid()}.tmp")
        tmp.write_text(json.dumps({"module": Path(target).name}))
        os.replace(tmp, path)
    except OSError:
        pass


def current_module(model_path, out_dir, methods=None, options=None, freeze=None):
    """The path of the generated module in ``out_dir`` that serves load(model_path, ...) without
    running the model file, or None (then load() runs it). See the module docstring."""
    try:
        entry = json.loads(entry_path(model_path, out_dir, options).read_text())
        target = Path(out_dir) / entry["module"]
        header = read_header(target)
        record = json.loads(derivation_record_path(target).read_text())
        text = Path(model_path).read_text()
    except (OSError, ValueError, KeyError, TypeError, UnicodeDecodeError):
        return None
    if not header or not isinstance(record, dict) or set(record) != _RECORD_FIELDS:
        return None
    disk = header.get("OPTIONS")
    if not isinstance(disk, dict) or not isinstance(header.get("MODEL_PATH"), str) or "SOURCES" not in header:
        return None
    if Path(os.path.normpath(target.parent / header["MODEL_PATH"])).resolve() != Path(model_path).resolve():
        return None
    data_files = record.get("data_files")
    if not isinstance(data_files, dict) or not isinstance(record.get("data"), dict):
        return None
    expected = {"model": model_hash(text), "data": {name: rec.get("sha256") for name, rec in data_files.items()
                                                     if isinstance(rec, dict)},
                "generator": generator_hash(), "options": disk, "key": header.get("KEY"), "data_files": data_files}
    if record != expected or changed_data_file(data_files) is not None:
        return None
    if why_stale(target, header.get("KEY"), header["SOURCES"], header.get("TEXT_SHA")):
        return None
    if options is not None and dict(options) != disk.get("build", {}):
        return None
    if freeze is not None and dict(sorted(freeze.items())) != disk.get("freeze", {}):
        return None
    if methods and not set(methods) <= set(disk.get("methods", ())):
        return None
    return target
