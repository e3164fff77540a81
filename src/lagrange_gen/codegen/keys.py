"""What a generated module was generated from, the stale check it runs on import, and the one
command that regenerates it (no sympy import: generated modules call check_current)."""

from __future__ import annotations

import hashlib
import json
import os
import shlex
from importlib import metadata
from pathlib import Path

from ..errors import StaleModuleError
from ..jit.sources import source_hashes

_PACKAGE = Path(__file__).resolve().parents[1]     # src/lagrange_gen
# Sources that shape the text generated from a model (equations, kernels, module layout, glue
# template): a change is seen by re-deriving (--check, load), not by the KEY. Hashed into the
# record load() keeps next to a module to skip re-deriving (codegen.generated_files.module_current).
_GENERATOR_PARTS = ("model", "run/params.py", "derive", "codegen", "steppers/core/registry.py")
# The header lines that record hashes of the rest of the file (a hash cannot hash itself).
KEY_PREFIX = "KEY = "
TEXT_SHA_PREFIX = "TEXT_SHA = "
_HEADER_FIELDS = ("KEY", "SOURCES", "TEXT_SHA", "OPTIONS", "MODEL_PATH")


def _version(dist):
    try:
        return metadata.version(dist)
    except metadata.PackageNotFoundError:
        return "unknown"


def generator_hash() -> str:
    """sha256 of the sources that shape generated text (_GENERATOR_PARTS) and the sympy version."""
    h = hashlib.sha256(f"sympy {_version('sympy')}".encode())
    for part in _GENERATOR_PARTS:
        path = _PACKAGE / part
        files = sorted(path.rglob("*.py")) if path.is_dir() else [path] if path.exists() else []
        for f in files:
            h.update(str(f.relative_to(_PACKAGE)).encode())
            h.update(f.read_bytes())
    return h.hexdigest()


def model_hash(source_text: str) -> str:
    return hashlib.sha256(source_text.encode()).hexdigest()


def _without_lines(text, prefixes):
    """``text`` without its lines that start with one of ``prefixes`` (and without line 1 when
    it records the KEY)."""
    lines = text.split("\n")
    if lines and lines[0].startswith("# lagrange-gen"):
        lines = lines[1:]
    return "\n".join(line for line in lines if not line.startswith(prefixes))


def text_hash(text: str) -> str:
    """sha256 of a generated module's text without its TEXT_SHA line (which records this hash)."""
    start = text.find("\n" + TEXT_SHA_PREFIX)
    if start >= 0:
        end = text.find("\n", start + 1)
        text = text[:start] + (text[end:] if end >= 0 else "")
    return hashlib.sha256(text.encode()).hexdigest()


def key_of_text(text: str) -> str:
    """KEY of a generated module: sha256 of its text without the KEY and TEXT_SHA lines. The
    text is the canonical form of what the module uses: its kernels as emitted (the derived
    equations, not the model file's text), OPTIONS, and SOURCES (hashes of the package
    sources its kernels compile), so the KEY changes exactly when one of those does."""
    return hashlib.sha256(_without_lines(text, (KEY_PREFIX, TEXT_SHA_PREFIX)).encode()).hexdigest()


def check_current(module_file, key, sources, model_relpath, options, text_sha):
    """Raise StaleModuleError when a generated module no longer matches what it uses.

    Called at import by every generated module (cheap, no sympy): its text against TEXT_SHA
    and KEY (a hand edit anywhere), and every package source its kernels compile against
    SOURCES (numba's on-disk cache is keyed on the generated file only, so a changed Cholesky
    routine must make the module stale; the stepper glue is keyed on the library's version by
    jit/specialized.py instead). A changed model file is seen by re-deriving:
    ``lagrange-gen --check`` and ``lagrange_gen.load``; at import, a model text or a file the
    model read or imported that differs from the one recorded when the module was last
    generated or checked (changed_input) is stale too, so a direct import never runs old kernels
    silently.
    """
    problem = why_stale(Path(module_file), key, sources, text_sha) or _model_changed(
        Path(module_file), model_relpath, key)
    if problem:
        raise StaleModuleError(f"{problem}: run {regeneration_command_from(module_file, model_relpath, options)}")


def derivation_record_path(target) -> Path:
    """Where generation records which model text, generator and options gave ``target`` (JSON,
    next to numba's cache, not in git): the model text must not enter the generated file."""
    target = Path(target)
    return target.parent / "__pycache__" / f"{target.stem}.lagrange-gen.json"


def read_derivation_record(target) -> dict | None:
    """The derivation record of the generated module ``target`` (a dict), or None when it is
    missing or unreadable."""
    try:
        record = json.loads(derivation_record_path(target).read_text())
    except (OSError, ValueError, UnicodeDecodeError):
        return None
    return record if isinstance(record, dict) else None


def changed_input(record, model_path) -> str | None:
    """The first input of a generated module whose content differs from its derivation
    ``record`` (read_derivation_record), or that is gone: the model file ``model_path``, then
    every file the model file read or imported while it ran (its data files, a Python file it
    exec()d, its helper modules: model.data_files). Its path, or None when all are as recorded.

    The one verdict on a module's inputs: the check every generated module runs on import, load
    and simulate of a model file (codegen.model_cache, without running the file), generation
    (which skips an unchanged model) and ``--check`` (which names the file) all ask it. Cheap:
    a recorded file whose size and mtime are unchanged is not read."""
    try:
        text = Path(model_path).read_text()
    except (OSError, UnicodeDecodeError):
        return str(model_path)
    if record.get("model") != model_hash(text):
        return str(model_path)
    inputs = record.get("data_files", {})
    return changed_data_file(inputs) if isinstance(inputs, dict) else str(model_path)


def input_change(changed, model_path, since) -> str:
    """The phrase saying that ``changed`` (from changed_input) changed since ``since`` was
    generated, and, for a file other than the model file ``model_path``, that the model reads it."""
    if os.path.realpath(changed) == os.path.realpath(model_path):
        return f"{_shown(model_path)} changed since {since} was generated"
    return (f"{_shown(changed)} changed since {since} was generated; {_shown(model_path)} reads or "
            "imports it")


def _model_changed(here, model_relpath, key):
    """A phrase when the model file or a file it read differs from the derivation record for
    this KEY (changed_input), else None (also None without a record, e.g. a fresh clone:
    --check re-derives to tell)."""
    record = read_derivation_record(here)
    if record is None or record.get("key") != key:
        return None
    model_path = here.parent / model_relpath
    changed = changed_input(record, model_path)
    if changed is None or (changed == str(model_path) and not model_path.is_file()):
        return None
    if changed == str(model_path):
        return (f"{input_change(changed, model_path, here)} (if only comments changed, "
                "regenerating leaves the module as it is)")
    return input_change(changed, model_path, here)


def changed_data_file(records) -> str | None:
    """The first path of ``records`` {path: {"sha256", "size", "mtime_ns"}} (model.data_files)
    whose content differs from the one recorded, or that is gone; else None. Cheap: a file whose
    size and mtime are the recorded ones is not read."""
    for path, old in sorted(records.items()):
        if not isinstance(old, dict) or not old:
            return path
        try:
            stat = os.stat(path)
            if stat.st_size == old.get("size") and stat.st_mtime_ns == old.get("mtime_ns"):
                continue
            digest = hashlib.sha256()
            with open(path, "rb") as fh:
                for block in iter(lambda: fh.read(1 << 20), b""):
                    digest.update(block)
        except OSError:
            return path
        if digest.hexdigest() != old.get("sha256"):
            return path
    return None


def check_fresh(module_file, key, model_sha, gen_sha, model_relpath, options, text_sha=None):
    """The check of modules written by lagrange-gen before SOURCES existed: always stale (the
    command regenerates the methods that apply: their OPTIONS may name methods that do not)."""
    here = Path(module_file).parent
    command = regeneration_command(_shown(here / model_relpath), _shown(here), options.get("build"), None,
                                   options.get("freeze"))
    raise StaleModuleError(f"{module_file} was generated by an older lagrange-gen: run {command}")


def why_stale(here, key, sources, text_sha):
    """Why the generated module ``here`` is stale as far as the import-time check sees (one
    phrase naming it), or None."""
    try:
        text = here.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError):
        text = None          # e.g. imported from a zip: nothing to compare with
    if text is not None and (text_hash(text) != text_sha or key_of_text(text) != key):
        return f"{here} was edited by hand since it was generated"
    changed = [name for name, sha in source_hashes(sources).items() if sha != sources[name]]
    if changed:
        return f"{here} is stale ({', '.join(changed)} changed since generation)"
    return None


def read_key(path) -> str | None:
    """The KEY recorded on a generated file's first line, or None when absent/unreadable."""
    try:
        with open(path, encoding="utf-8") as fh:
            first = fh.readline()
    except (OSError, UnicodeDecodeError):
        return None
    marker = KEY_PREFIX
    return first.split(marker, 1)[1].strip() if first.startswith("# lagrange-gen") and marker in first else None


def read_header(path) -> dict | None:
    """{KEY, SOURCES, TEXT_SHA, OPTIONS, MODEL_PATH: value} of a generated file
    (fields it lacks are absent), or None when ``path`` is not a readable generated module."""
    import ast
    if read_key(path) is None:
        return None
    header, started = {}, False
    with open(path, encoding="utf-8") as fh:
        for line in fh:
            if line.startswith(("check_current(", "check_fresh(")):
                break
            started = started or line.startswith("# fmt: off")   # the docstring is above this
            name, sep, value = line.partition(" = ")
            if started and sep and name in _HEADER_FIELDS:
                try:
                    header[name] = ast.literal_eval(value.strip())
                except (ValueError, SyntaxError):
                    pass
    return header


def default_generated_dir(model_path) -> Path:
    """Where the modules generated from ``model_path`` go unless -o / out_dir= says otherwise,
    the same from any working directory: ``<project>/generated`` for a model file in a folder
    named ``models`` (this repository's layout: models/x.py -> generated/x.py), else
    ``generated`` beside the model file. Relative to the working directory when below it."""
    folder = Path(os.path.abspath(model_path)).parent
    base = folder.parent if folder.name == "models" else folder
    return Path(_shown(base / "generated"))


def regeneration_command(model_path, out_dir=None, build=None, methods=None, freeze=None,
                         sensitivities=False) -> str:
    """The shell command that generates ``model_path`` into ``out_dir`` with these options
    (paths quoted; -o omitted for the model's default_generated_dir, and for out_dir None;
    --methods omitted for the methods that apply to the model, the default): the one source of
    every "run lagrange-gen ..." hint."""
    from ..steppers.core.registry import METHODS, applicable_methods
    defaults = [set(applicable_methods(*counts))
                for counts in ((0, 0, 0, 0), (1, 0, 0, 0), (0, 1, 0, 0), (0, 0, 1, 0), (0, 0, 0, 1))]
    args = ["lagrange-gen", str(model_path)]
    if out_dir is not None and (os.path.abspath(out_dir)
                                != os.path.abspath(default_generated_dir(model_path))):
        args += ["-o", str(out_dir)]
    for name, value in sorted((build or {}).items()):
        args += ["--set", f"{name}={value}"]
    if methods is not None and set(methods) not in defaults:
        args += ["--methods", ",".join(m for m in METHODS if m in set(methods))]
    if freeze:
        args += ["--freeze", ",".join(f"{k}={v!r}" for k, v in sorted(freeze.items()))]
    if sensitivities:
        args.append("--sensitivities")
    return shlex.join(args)


def _shown(path) -> str:
    """``path`` relative to the working directory when it is below it, else absolute."""
    relative = os.path.relpath(os.path.abspath(path))
    return os.path.abspath(path) if relative.startswith("..") else relative


def regeneration_command_from(module_file, model_relpath, options, methods=()) -> str:
    """The command regenerating the generated module ``module_file`` (MODEL_PATH and OPTIONS from
    its header) in place, with the ``methods`` it lacks added; paths shown from the current
    working directory."""
    here = Path(module_file).parent
    have = list(options.get("methods", ()))
    return regeneration_command(_shown(here / model_relpath), _shown(here), options.get("build"),
                                have + [m for m in methods if m not in have], options.get("freeze"),
                                options.get("sensitivities", False))


def regeneration_command_for(module, methods=()) -> str:
    """The command that regenerates an imported generated ``module`` in place (same model file,
    output directory, build options and freeze) with ``methods`` added to its own, e.g. for
    "generated without method X" hints: ``regeneration_command_for(mod, methods=["midpoint"])``."""
    return regeneration_command_from(module.__file__, module.MODEL_PATH, module.OPTIONS, methods)
