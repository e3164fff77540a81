"""The generation pipeline for one model file: load -> derive -> kernels -> render -> write.

Also what ``--check`` and ``lagrange_gen.load`` decide from a generated file on disk: whether
its text is what the generator would write now (check_generated), and whether it can be used
for a request or must be generated (plan_load).
"""

from __future__ import annotations

import ast
import json
import os
import sys
import threading
import time
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

from .compose import compositions
from .compose import make_kernels
from ..derive import derive
from .emit import render_kernel
from ..errors import GenerationError
from .keys import (derivation_record_path, generator_hash, key_of_text, model_hash, read_header, regeneration_command,
                    text_hash, why_stale)
from ..model.model_file import load_model
from .needs import methods_needs, select_kernels
from .printer import Inputs
from .render import COMPILED_IMPORTS, render_module
from .sources import source_closure, source_hashes
from .write import write_if_changed

#: Seconds a generation stage may run before progress lines go to stderr (small models: none).
PROGRESS_AFTER = 2.0
#: Seconds between the lines of a stage that is still running.
PROGRESS_EVERY = 30.0


@dataclass
class GenerationResult:
    path: Path
    written: bool
    key: str


def output_path(model_name: str, out_dir) -> Path:
    return Path(out_dir) / f"{model_name}.py"


class Progress:
    """Progress lines on stderr for one generation (``label`` names the model file): a stage
    still running after PROGRESS_AFTER s is announced, again every PROGRESS_EVERY s with what it
    is doing (``detail``), and its end reported with the elapsed time; fast stages print nothing."""

    def __init__(self, label):
        self.label, self.detail = str(label), ""
        self._lock = threading.Lock()

    def say(self, text):
        with self._lock:
            print(f"lagrange-gen: {self.label}: {text}", file=sys.stderr, flush=True)

    @contextmanager
    def stage(self, name):
        start, done = time.perf_counter(), threading.Event()
        self.detail = ""
        watcher = threading.Thread(target=self._watch, args=(name, start, done), daemon=True)
        watcher.start()
        try:
            yield self
        finally:
            done.set()
            watcher.join()
        elapsed = time.perf_counter() - start
        if elapsed >= PROGRESS_AFTER:
            self.say(f"{name} done in {elapsed:.1f} s")

    def _watch(self, name, start, done):
        wait = PROGRESS_AFTER
        while not done.wait(wait):
            detail = f": {self.detail}" if self.detail else ""
            self.say(f"{name} running ({time.perf_counter() - start:.0f} s){detail}")
            wait = PROGRESS_EVERY


def generation_options(build, methods, freeze):
    """Generation options recorded in the module and hashed into its KEY."""
    options = {"build": dict(sorted(build.items())), "methods": list(methods)}
    if freeze:
        options["freeze"] = dict(sorted(freeze.items()))
    return options


def model_counts(model):
    """(number of constraints, of nonsmooth elements, of contacts, of nonholonomic constraints):
    what decides the methods that apply."""
    return (len(model.constraints), len(model.elements), len(getattr(model, "contacts", ())),
            len(getattr(model, "nonholonomic", ())))


def resolve_methods(requested, model, drop_inapplicable=False):
    """Methods to emit glue for, in registry order: for None those that apply to ``model``
    (steppers.registry.applicable_methods), else the requested ones, implicit_euler becoming
    nonsmooth_euler on a model with elements as in simulate. GenerationError for an unknown
    method, and for one that does not apply (one line naming it and why) unless
    ``drop_inapplicable`` (load(): simulate then refuses it with its own message)."""
    from ..steppers.core.registry import METHODS, applicable_methods, inapplicable, runs_as
    counts = model_counts(model)
    n_elements = counts[1]
    if requested is None:
        return list(applicable_methods(*counts))
    unknown = [m for m in requested if m not in METHODS]
    if unknown:
        raise GenerationError(f"unknown method(s) {', '.join(unknown)}; known: {', '.join(METHODS)}")
    wanted = {runs_as(m, n_elements) for m in requested}
    for method in (m for m in METHODS if m in wanted):
        why = inapplicable(method, *counts)
        if why and not drop_inapplicable:
            raise GenerationError(f"method {method} does not apply to model {model.name!r}: {why}")
        if why:
            wanted.discard(method)
    return [m for m in METHODS if m in wanted]


@dataclass
class GenerationParts:
    """Everything one generation produced: the text and what the scale benchmark reports.

    texts: one emit.KernelText per kernel; seconds: {"derive": model -> symbolic kernels
    (Jacobians are derived here, on demand), "emit": CSE + printing + module text}.
    """

    text: str
    key: str
    target: Path
    dyn: object
    texts: list
    seconds: dict


def generate_parts(model, out_dir="generated", methods=None, freeze=None, progress=None) -> GenerationParts:
    """Derive and emit a loaded Model (nothing is written); see generate_text."""
    progress = progress or Progress(model.source_path or model.name)
    methods, freeze = resolve_methods(methods, model), dict(sorted((freeze or {}).items()))
    options = generation_options(model.build_options, methods, freeze)
    start = time.perf_counter()
    with progress.stage("derive"):
        dyn = derive(model, freeze=freeze)
        selected = select_kernels(dyn, methods)
        composed = compositions(dyn, selected, methods_needs(methods)) if methods else {}
        for name, how in composed.items():
            selected[name] = selected[name] + [f"composed from kernels ({how})"]
        kernels = make_kernels(dyn, selected, composed)
    derived = time.perf_counter()
    with progress.stage("emit"):
        inputs, texts = Inputs(dyn), []
        for number, spec in enumerate(kernels, 1):
            progress.detail = f"kernel {number}/{len(kernels)} {spec.name}"
            texts.append(render_kernel(spec, inputs))
        target = output_path(model.name, out_dir)
        source_rel = os.path.relpath(Path(model.source_path or ".").resolve(), Path(out_dir).resolve())
        text = render_module(dyn, texts, sources=module_sources(methods), options=options,
                             source_rel=source_rel, methods=methods,
                             glue=_glue(methods, dyn),
                             why=selected)
    seconds = {"derive": derived - start, "emit": time.perf_counter() - derived}
    return GenerationParts(text, key_of_text(text), target, dyn, texts, seconds)


def _glue(methods, dyn):
    """The glue of every method: run_<method>, then (fixed-step methods) ensemble_<method>."""
    from .glue import ensemble_glue_source, glue_source
    from ..steppers.core.registry import spec
    blocks = []
    for m in methods:
        counts = (_n_saved(m, dyn), len(dyn.model.events))
        blocks.append(glue_source(m, *counts))
        if not spec(m).adaptive:
            blocks.append(ensemble_glue_source(m, *counts))
    return "\n\n".join(blocks)


def _n_saved(method, dyn):
    from ..steppers.core.registry import spec
    return spec(method).n_saved(dyn.n, dyn.m, dyn.n_elements, dyn.n_contacts, dyn.n_nonholonomic)


def module_sources(methods) -> dict:
    """{package file: hash} of what a module gluing ``methods`` compiles: the stepper modules,
    the run loops their glue calls (registry.LOOPS), the package modules they import and the
    compiled imports of every module (linalg, status)."""
    from ..steppers.core.registry import LOOPS, spec
    loops = sorted({f"steppers.core.{LOOPS[spec(m).adaptive][0]}" for m in methods})
    return source_hashes(source_closure([f"steppers.methods.{m}" for m in methods] + loops
                                        + list(COMPILED_IMPORTS)))


def generate_text(model, out_dir="generated", methods=None, freeze=None):
    """Return (module text, KEY, target path) for a loaded Model; nothing is written.

    methods: stepper methods to emit glue for (default: those that apply to the model); only the
    kernels they reach are derived and emitted (codegen.needs). freeze: {parameter: value}
    folded into the kernels.
    """
    parts = generate_parts(model, out_dir, methods, freeze)
    return parts.text, parts.key, parts.target


def _label(model_path, options):
    return " ".join([str(model_path)] + [f"--set {k}={v}" for k, v in sorted((options or {}).items())])


def generate_model(model_path, out_dir="generated", methods=None, options=None,
                   freeze=None, force=False) -> GenerationResult:
    """Generate out_dir/<name>.py from a model file (atomic; unchanged files are not touched).

    A file there generated from another model file (or not by lagrange-gen) is not overwritten
    unless ``force`` (GenerationError naming both files)."""
    progress = Progress(_label(model_path, options))
    with progress.stage("load model"):
        model = load_model(model_path, **(options or {}))
    target = output_path(model.name, out_dir)
    if not force:
        refuse_overwrite(model_path, target, model.name)
    parts = generate_parts(model, out_dir, methods, freeze, progress)
    with progress.stage("write"):
        written = write_if_changed(target, parts.text)
    remember_current(target, model, parts.key, read_header(target)["OPTIONS"])
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
    """What makes re-deriving needless: the same model text, data files it read (their sha256),
    generator sources, options and KEY."""
    data = {name: rec.get("sha256") for name, rec in getattr(model, "data_files", {}).items()}
    return {"model": model_hash(model.source_text), "data": data, "generator": generator_hash(),
            "options": options, "key": key}


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
        text, key, _ = generate_text(model, target.parent, options.get("methods"), options.get("freeze"))
    except GenerationError:
        return False                      # e.g. methods that no longer apply
    if text != target.read_text(encoding="utf-8"):
        return False
    remember_current(target, model, key, options)
    return True


def is_current(model_path, out_dir="generated", methods=None, options=None, freeze=None):
    """(target, True when target is what generating the model with these arguments writes now):
    the decision of load(), re-deriving only when the model file or the generator changed since
    the last time it was made (module_current); check_generated always re-derives."""
    model = load_model(model_path, **(options or {}))
    target = output_path(model.name, out_dir)
    header = read_header(target)
    freeze = dict(sorted((freeze or {}).items()))
    wanted = generation_options(model.build_options, resolve_methods(methods, model), freeze)
    return target, header is not None and header.get("OPTIONS") == wanted and module_current(model, target, header)


def check_generated(model_path, out_dir="generated", methods=None, options=None, freeze=None):
    """(target, None) when the file on disk is exactly what generating with these arguments would
    write now, else (target, "missing" or "stale (why)"). Re-derives: a changed data file or
    helper module the model reads is seen when it changes the equations, and only then."""
    model = load_model(model_path, **(options or {}))
    target = output_path(model.name, out_dir)
    header = read_header(target)
    if header is None:
        return target, "stale (not a lagrange-gen module)" if target.exists() else "missing"
    other = other_source(model_path, target, header)
    if other is not None:
        return target, f"stale (generated from {other}, not {model_path})"
    parts = generate_parts(model, out_dir, methods, freeze)
    try:
        on_disk = target.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        return target, f"stale (unreadable: {exc})"
    if on_disk == parts.text:
        remember_current(target, model, parts.key, header.get("OPTIONS"))
        return target, None
    return target, f"stale ({_difference(header, on_disk, parts.text)})"


def _difference(header, on_disk, text):
    """Why the generated text ``on_disk`` (its ``header``) differs from ``text``, the text
    generating writes now: a phrase."""
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
        return f"stepper sources changed: {', '.join(sorted({name for name, _ in changed}))}"
    return "its equations changed: the model, a file it reads or imports, or the generator changed"


def describe_options(options) -> str:
    """Recorded generation options as command-line options ('--set n=8 --freeze g=1.62'), or
    'default options'."""
    command = regeneration_command("M", "generated", options.get("build"), options.get("methods"),
                                   options.get("freeze"))
    return command.split(" ", 2)[2] if command.count(" ") >= 2 else "default options"
