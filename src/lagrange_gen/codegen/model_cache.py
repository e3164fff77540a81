"""The memory of the model files that were run: which generated module a model file gave, so
that loading or generating the same unchanged file again finds its module without running the
file (running a robot's model file costs seconds: building its mechanics frames and bodies in
sympy; deriving it again, seconds more). Light: no sympy.

An entry is keyed by the content that decides what the file builds: its resolved path, its text,
the build options (``--set``) and the generator's sources (keys.generator_hash, which covers
model/, derive/, codegen/). It names the module the file gave; ``lagrange_gen.load`` and
generation (codegen.generated_files.generate_model) write it. The module serves a later load or
generation only when, read from disk without sympy: the module was generated from this file,
its derivation record (written by generation next to numba's cache) says it was generated with
this generator and these options, the model file and every file it read or imported while it
ran are as recorded (keys.changed_input: the one verdict on a module's inputs), its text and the
package sources it compiles are unchanged (keys.why_stale), and it has what is asked (load:
the methods, freeze and build options asked for; generation: exactly those). Anything else - no
entry, a record with fields this check does not know, a missing method - goes the ordinary way:
run the file, re-derive if needed.
"""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path

from .keys import changed_input, generator_hash, read_derivation_record, read_header, why_stale

#: The fields of a derivation record this check compares (codegen.generated_files._record and the
#: data files' sizes and times that remember_current adds).
_RECORD_FIELDS = {"model", "data", "generator", "options", "key", "applicable", "data_files"}


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


def current_module(model_path, out_dir, methods=None, options=None, freeze=None,
                   sensitivities=False):
    """The path of the generated module in ``out_dir`` that serves load(model_path, ...) without
    running the model file, or None (then load() runs it): current, and it has the ``methods``
    (None: any), the ``freeze`` and the build ``options`` (None: whatever it has)."""
    found = _current(model_path, out_dir, options)
    if found is None:
        return None
    target, disk, _ = found
    if options is not None and dict(options) != disk.get("build", {}):
        return None
    if freeze is not None and dict(sorted(freeze.items())) != disk.get("freeze", {}):
        return None
    if methods and not set(methods) <= set(disk.get("methods", ())):
        return None
    if sensitivities and not disk.get("sensitivities", False):
        return None
    return target


def generation_current(model_path, out_dir, methods=None, options=None, freeze=None,
                       sensitivities=False):
    """The path of the generated module in ``out_dir`` that generating ``model_path`` with these
    arguments would write again unchanged, found without running the model file (nor importing
    sympy or the steppers); else None (then generation runs it). Exactly these options: build
    ``options`` and ``freeze`` (None: none), ``methods`` (None: those that apply to the model,
    recorded at generation). Requested methods are compared as given: one that generation would
    rename (implicit_euler on a model with nonsmooth elements), drop or refuse is not among the
    module's, so the ordinary way decides (and says why in one line)."""
    found = _current(model_path, out_dir, options or {})
    if found is None:
        return None
    target, disk, record = found
    wanted = record.get("applicable") if methods is None else list(methods)
    if (not isinstance(wanted, list)
            or disk.get("build", {}) != dict(options or {})
            or disk.get("freeze", {}) != dict(sorted((freeze or {}).items()))
            or set(disk.get("methods", ())) != set(wanted)
            or disk.get("sensitivities", False) != bool(sensitivities)):
        return None
    return target


def _current(model_path, out_dir, options):
    """(target, its OPTIONS, its derivation record) when the entry of ``model_path`` (with build
    ``options``) names a module in ``out_dir`` that is current: generated from this file, by
    this generator, from inputs all as recorded (keys.changed_input), its text and compiled
    sources unchanged. Else None."""
    try:
        entry = json.loads(entry_path(model_path, out_dir, options).read_text())
        target = Path(out_dir) / entry["module"]
        header = read_header(target)
    except (OSError, ValueError, KeyError, TypeError, UnicodeDecodeError):
        return None
    record = read_derivation_record(target)
    if not header or record is None or set(record) != _RECORD_FIELDS:
        return None
    disk = header.get("OPTIONS")
    if not isinstance(disk, dict) or not isinstance(header.get("MODEL_PATH"), str) or "SOURCES" not in header:
        return None
    if Path(os.path.normpath(target.parent / header["MODEL_PATH"])).resolve() != Path(model_path).resolve():
        return None
    data_files = record.get("data_files")
    if not isinstance(data_files, dict) or record.get("data") != {
            name: rec.get("sha256") for name, rec in data_files.items() if isinstance(rec, dict)}:
        return None
    if (record.get("generator"), record.get("options"), record.get("key")) != (
            generator_hash(), disk, header.get("KEY")):
        return None
    if changed_input(record, model_path) is not None:
        return None
    if why_stale(target, header.get("KEY"), header["SOURCES"], header.get("TEXT_SHA")):
        return None
    return target, disk, record
