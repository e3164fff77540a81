"""The generated file on disk: write it from a model file (generate_model), refuse to overwrite
what another model file or a person wrote, record what it was generated from (the derivation
record beside numba's cache: model text, data files, generator sources, options, KEY), and
decide whether it is current: cheaply from that record for ``lagrange_gen.load``
(module_current, is_current), or by generating the text again for ``--check``
(check_generated), with a phrase saying why it is stale.
"""

from __future__ import annotations

import ast
import json
import os
from pathlib import Path

from ..errors import GenerationError
from .generate import (GenerationResult, Progress, generate_parts, generate_text, generation_options,
                       output_path, resolve_methods)
from .keys import (changed_input, default_generated_dir, derivation_record_path, generator_hash,
                   input_change, key_of_text, model_hash, read_derivation_record, read_header,
                   regeneration_command, text_hash, why_stale)
from .model_cache import generation_current, remember_module
from ..model.model_file import load_model
from .write import write_if_changed

__all__ = ["generate_model", "check_generated", "is_current", "module_current", "remember_current",
           "refuse_overwrite", "other_source", "describe_options"]


def _label(model_path, options):
    return " ".join([str(model_path)] + [f"--set {k}={v}" for k, v in sorted((options or {}).items())])


def generate_model(model_path, out_dir=None, methods=None, options=None,
                   freeze=None, force=False, model=None, sensitivities=False) -> GenerationResult:
    """Generate out_dir/<name>.py from a model file (atomic; unchanged files are not touched).
    out_dir None: keys.default_generated_dir of the model file.

    A module there that is current - generated from this model file with these options, by this
    generator, and the model file and everything it read or imported unchanged since
    (model_cache.generation_current) - is kept without running the model file or deriving:
    the result says ``current``. ``force`` derives and writes it again, and overwrites a file
    generated from another model file (or not by lagrange-gen), which is otherwise refused
    (GenerationError naming both files). ``model``: the Model this model file gave with these
    ``options``, when the caller has run it already (it is not run a second time).
    ``sensitivities``: with the parameter derivatives of forward sensitivities."""
    out_dir = default_generated_dir(model_path) if out_dir is None else out_dir
    if not force:
        known = generation_current(model_path, out_dir, methods, options, freeze, sensitivities)
        if known is not None:
            return GenerationResult(known, False, read_header(known)["KEY"], current=True)
    progress = Progress(_label(model_path, options))
    if model is None or model.build_options != dict(options or {}):
        with progress.stage("load model"):
            model = load_model(model_path, **(options or {}))
    target = output_path(model.name, out_dir)
    if not force:
        refuse_overwrite(model_path, target, model.name)
    parts = generate_parts(model, out_dir, methods, freeze, progress, sensitivities)
    with progress.stage("write"):
        written = write_if_changed(target, parts.text)
    remember_current(target, model, parts.key, read_header(target)["OPTIONS"])
    remember_module(model_path, out_dir, options or {}, target)
    return GenerationResult(target, written, parts.key)


def other_source(model_path, target, header):
    """The model file ``target`` was generated from when it is not ``model_path`` and exists."""
    recorded = header.get("MODEL_PATH")
    if not isinstance(recorded, str):
        return None
    source = Path(os.path.normpath(target.parent / recorded))
    if not source.is_file() or source.resolve() == Path(model_path).resolve():
        return None
    return source


def refuse_overwrite(model_path, target, name):
    """GenerationError when ``target`` holds something generating ``model_path`` (model ``name``)
    would destroy: a module generated from another existing model file, or a file that
    lagrange-gen did not write."""
    if not target.is_file() or target.stat().st_size == 0:
        return
    header = read_header(target)
    if header is None:
        raise GenerationError(f"{target} exists and was not written by lagrange-gen: not overwritten "
                              f"(move it, use another -o DIR, or pass --force)")
    other = other_source(model_path, target, header)
    if other is not None:
        raise GenerationError(f"{target} was generated from {other}, not {model_path} (both define model "
                              f"{name!r}): not overwritten (rename one model, use another -o DIR, or pass --force)")


def _record(model, key, options) -> dict:
    """What makes re-deriving needless: the same model text, files it read or imported (their
    sha256), generator sources, options and KEY; and the methods that apply to the model (what
    generation without --methods glues, known without running the model file)."""
    data = {name: rec.get("sha256") for name, rec in getattr(model, "data_files", {}).items()}
    return {"model": model_hash(model.source_text), "data": data, "generator": generator_hash(),
            "options": options, "key": key, "applicable": resolve_methods(None, model)}


def _recorded(path) -> dict:
    """The record of remember_current at ``path`` without the data files' sizes and mtimes
    (which only make the import-time check cheap, keys.check_current); {} when unreadable."""
    record = json.loads(path.read_text())
    if not isinstance(record, dict):
        return {}
    record.pop("data_files", None)
    return record


def remember_current(target, model, key, options):
    """Record that ``target`` (KEY ``key``) is what ``model`` generates with ``options`` now; the
    model text's hash goes here, never into the generated file (a comment edit must not change it).
    Best effort: an unwritable directory only means load() re-derives next time."""
    path = derivation_record_path(target)
    try:
        path.parent.mkdir(exist_ok=True)
        tmp = path.with_suffix(f".{os.getpid()}.tmp")
        record = _record(model, key, options)
        record["data_files"] = getattr(model, "data_files", {})
        tmp.write_text(json.dumps(record, sort_keys=True))
        os.replace(tmp, path)
    except OSError:
        pass


def module_current(model, target, header) -> bool:
    """True when ``target`` (its ``header``: keys.read_header) is what generating ``model`` with
    the header's OPTIONS writes now. Cheap when the record of remember_current matches (model
    text, generator sources, options, KEY); otherwise re-derives and compares the text (about
    50 ms for the models in models/), recording the answer when current."""
    options = header.get("OPTIONS")
    if "SOURCES" not in header or not isinstance(options, dict):
        return False                      # not a module of this lagrange-gen
    if why_stale(target, header.get("KEY"), header["SOURCES"], header.get("TEXT_SHA")):
        return False
    try:
        if _recorded(derivation_record_path(target)) == _record(model, header["KEY"], options):
            return True
    except (OSError, ValueError):
        pass
    try:
        text, key, _ = generate_text(model, target.parent, options.get("methods"), options.get("freeze"),
                                     options.get("sensitivities", False))
    except GenerationError:
        return False                      # e.g. methods that no longer apply
    if text != target.read_text(encoding="utf-8"):
        return False
    remember_current(target, model, key, options)
    return True


def is_current(model_path, out_dir=None, methods=None, options=None, freeze=None):
    """(target, True when target is what generating the model with these arguments writes now):
    the decision of load(), re-deriving only when the model file or the generator changed since
    the last time it was made (module_current); check_generated always re-derives."""
    out_dir = default_generated_dir(model_path) if out_dir is None else out_dir
    model = load_model(model_path, **(options or {}))
    target = output_path(model.name, out_dir)
    header = read_header(target)
    freeze = dict(sorted((freeze or {}).items()))
    wanted = generation_options(model.build_options, resolve_methods(methods, model), freeze)
    return target, header is not None and header.get("OPTIONS") == wanted and module_current(model, target, header)


def check_generated(model_path, out_dir=None, methods=None, options=None, freeze=None,
                    sensitivities=False):
    """(target, None) when the file on disk is exactly what generating with these arguments would
    write now, else (target, "missing" or "stale (why)"). Re-derives: a changed data file or
    helper module the model reads is seen when it changes the equations, and only then."""
    out_dir = default_generated_dir(model_path) if out_dir is None else out_dir
    model = load_model(model_path, **(options or {}))
    target = output_path(model.name, out_dir)
    header = read_header(target)
    if header is None:
        return target, "stale (not a lagrange-gen module)" if target.exists() else "missing"
    other = other_source(model_path, target, header)
    if other is not None:
        return target, f"stale (generated from {other}, not {model_path})"
    parts = generate_parts(model, out_dir, methods, freeze, sensitivities=sensitivities)
    try:
        on_disk = target.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        return target, f"stale (unreadable: {exc})"
    if on_disk == parts.text:
        remember_current(target, model, parts.key, header.get("OPTIONS"))
        return target, None
    return target, f"stale ({_difference(header, on_disk, parts.text, model_path, target)})"


def _difference(header, on_disk, text, model_path, target):
    """Why the generated text ``on_disk`` (its ``header``) differs from ``text``, the text
    generating writes now: a phrase, naming the model's input that changed when the derivation
    record tells (keys.changed_input)."""
    if "SOURCES" not in header:
        return "generated by an older lagrange-gen"
    if text_hash(on_disk) != header.get("TEXT_SHA") or key_of_text(on_disk) != header.get("KEY"):
        return "edited by hand since it was generated"
    new = {}
    for line in text.split("\n"):
        name, sep, value = line.partition(" = ")
        if sep and name in ("OPTIONS", "SOURCES") and name not in new:
            new[name] = ast.literal_eval(value)
    if header.get("OPTIONS") != new.get("OPTIONS"):
        return f"generated with other options: {describe_options(header.get('OPTIONS') or {})}"
    if header.get("SOURCES") != new.get("SOURCES"):
        changed = sorted(set((header.get("SOURCES") or {}).items()) ^ set(new["SOURCES"].items()))
        return f"kernel sources changed: {', '.join(sorted({name for name, _ in changed}))}"
    record = read_derivation_record(target)
    changed = (changed_input(record, model_path)
               if record is not None and record.get("key") == header.get("KEY") else None)
    if changed is not None:
        return f"its equations changed: {input_change(changed, model_path, target)}"
    return "its equations changed: the model, a file it reads or imports, or the generator changed"


def describe_options(options) -> str:
    """Recorded generation options as command-line options ('--set n=8 --freeze g=1.62'), or
    'default options'."""
    command = regeneration_command("M", None, options.get("build"), options.get("methods"),
                                   options.get("freeze"), options.get("sensitivities", False))
    return command.split(" ", 2)[2] if command.count(" ") >= 2 else "default options"
