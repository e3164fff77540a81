"""The generation pipeline for one model: derive -> kernels -> render, as text and parts.

Writing the text to generated/<name>.py and deciding whether a file on disk is current are in
codegen/generated_files.py.
"""

from __future__ import annotations

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
from .keys import key_of_text
from .needs import methods_needs, select_kernels
from .printer import Inputs
from .render import COMPILED_IMPORTS, render_module
from ..jit.sources import source_closure, source_hashes

#: Seconds a generation stage may run before progress lines go to stderr (small models: none).
PROGRESS_AFTER = 2.0
#: Seconds between the lines of a stage that is still running.
PROGRESS_EVERY = 30.0


@dataclass
class GenerationResult:
    """path: the generated module; written: its file changed; key: its KEY; current: found
    current without running the model file (nothing derived)."""

    path: Path
    written: bool
    key: str
    current: bool = False


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


def generation_options(build, methods, freeze, sensitivities=False):
    """Generation options recorded in the module and hashed into its KEY ("sensitivities" only
    when asked: a module without them is the one generated before they existed)."""
    options = {"build": dict(sorted(build.items())), "methods": list(methods)}
    if freeze:
        options["freeze"] = dict(sorted(freeze.items()))
    if sensitivities:
        options["sensitivities"] = True
    return options


def model_counts(model):
    """(number of constraints, of nonsmooth elements, of contacts, of nonholonomic constraints):
    what decides the methods that apply."""
    return (len(model.constraints), len(model.elements), len(getattr(model, "contacts", ())),
            len(getattr(model, "nonholonomic", ())))


def resolve_methods(requested, model, drop_inapplicable=False):
    """Methods a module runs, in registry order: for None those that apply to ``model``
    (steppers.registry.applicable_methods), else the requested ones, implicit_euler becoming
    nonsmooth_euler on a model with elements as in simulate. GenerationError for an unknown
    method, and for one that does not apply (one line naming it and why) unless
    ``drop_inapplicable`` (load(): simulate then refuses it with its own message)."""
    from ..steppers.core.registry import (METHODS, applicable_methods, inapplicable, runs_as,
                                          unknown_method)
    counts = model_counts(model)
    n_elements = counts[1]
    if requested is None:
        return list(applicable_methods(*counts))
    unknown = [m for m in requested if m not in METHODS]
    if unknown:
        raise GenerationError(unknown_method(unknown[0]) if len(unknown) == 1 else
                              f"unknown methods {', '.join(unknown)}; known: {', '.join(METHODS)}")
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


def generate_parts(model, out_dir="generated", methods=None, freeze=None, progress=None,
                   sensitivities=False) -> GenerationParts:
    """Derive and emit a loaded Model (nothing is written); see generate_text."""
    progress = progress or Progress(model.source_path or model.name)
    methods, freeze = resolve_methods(methods, model), dict(sorted((freeze or {}).items()))
    options = generation_options(model.build_options, methods, freeze, sensitivities)
    start = time.perf_counter()
    with progress.stage("derive"):
        dyn = derive(model, freeze=freeze)
        selected = select_kernels(dyn, methods, sensitivities)
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
        text = render_module(dyn, texts, sources=module_sources(), options=options,
                             source_rel=source_rel, methods=methods, why=selected)
    seconds = {"derive": derived - start, "emit": time.perf_counter() - derived}
    return GenerationParts(text, key_of_text(text), target, dyn, texts, seconds)


def module_sources() -> dict:
    """{package file: hash} of what a module's kernels compile besides their own text (the
    Cholesky routines and status codes, COMPILED_IMPORTS, and what they import): the kernels'
    ABI. The stepper glue is not in it: the library writes it, keyed on its own version
    (jit/specialized.py), so a changed stepper leaves generated modules current."""
    return source_hashes(source_closure(list(COMPILED_IMPORTS)))


def generate_text(model, out_dir="generated", methods=None, freeze=None, sensitivities=False):
    """Return (module text, KEY, target path) for a loaded Model; nothing is written.

    methods: stepper methods the module runs (default: those that apply to the model); only the
    kernels they reach are derived and emitted (codegen.needs). freeze: {parameter: value}
    folded into the kernels. sensitivities: also the parameter derivatives the methods' forward
    sensitivities need (lagrange_gen.simulate(sensitivities=...)).
    """
    parts = generate_parts(model, out_dir, methods, freeze, sensitivities=sensitivities)
    return parts.text, parts.key, parts.target
