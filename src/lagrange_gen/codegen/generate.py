"""The generation pipeline for one model file: load -> derive -> kernels -> render -> write."""

from __future__ import annotations

import os
import time
from dataclasses import dataclass
from pathlib import Path

from ..derive import derive
from ..errors import GenerationError
from ..model import load_model
from ..keys import generator_hash, make_key, model_hash, read_key
from .emit import render_kernel
from .compose import compositions
from .needs import methods_needs, select_kernels
from .printer import Inputs
from .render import render_module
from .spec import make_kernels
from .write import write_if_changed


@dataclass
class GenerationResult:
    path: Path
    written: bool
    key: str


def output_path(model_name: str, out_dir) -> Path:
    return Path(out_dir) / f"{model_name}.py"


def _command(model_path, out_dir, options, methods=None, freeze=None):
    """The command that regenerates this very module (quoted in stale-module errors)."""
    from ..steppers.registry import METHODS
    cmd = f"lagrange-gen {model_path}"
    if str(out_dir) != "generated":
        cmd += f" -o {out_dir}"
    for k, v in sorted(options.items()):
        cmd += f" --set {k}={v}"
    if methods is not None and list(methods) != list(METHODS):
        cmd += f" --methods {','.join(methods)}"
    if freeze:
        cmd += " --freeze " + ",".join(f"{k}={v!r}" for k, v in sorted(freeze.items()))
    return cmd


def _options(model, methods, freeze):
    """Generation options recorded in the module and hashed into its KEY."""
    options = {"build": dict(sorted(model.build_options.items())), "methods": list(methods)}
    if freeze:
        options["freeze"] = dict(sorted(freeze.items()))
    return options


def _methods(requested):
    from ..steppers.registry import METHODS
    if requested is None:
        return list(METHODS)
    unknown = [m for m in requested if m not in METHODS]
    if unknown:
        raise GenerationError(f"unknown method(s) {', '.join(unknown)}; known: {', '.join(METHODS)}")
    return [m for m in METHODS if m in requested]


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


def generate_parts(model, out_dir="generated", methods=None, freeze=None) -> GenerationParts:
    """Derive and emit a loaded Model (nothing is written); see generate_text."""
    from ..steppers.registry import glue_source
    methods, freeze = _methods(methods), dict(sorted((freeze or {}).items()))
    options = _options(model, methods, freeze)
    model_sha, gen_sha = model_hash(model.source_text), generator_hash()
    key = make_key(model_sha, gen_sha, options)
    start = time.perf_counter()
    dyn = derive(model, freeze=freeze)
    selected = select_kernels(dyn, methods)
    composed = compositions(dyn, selected, methods_needs(methods)) if methods else {}
    for name, how in composed.items():
        selected[name] = selected[name] + [f"composed from kernels ({how})"]
    kernels = make_kernels(dyn, selected, composed)
    derived = time.perf_counter()
    inputs = Inputs(dyn)
    texts = [render_kernel(spec, inputs) for spec in kernels]
    target = output_path(model.name, out_dir)
    source_rel = os.path.relpath(Path(model.source_path or ".").resolve(), Path(out_dir).resolve())
    text = render_module(dyn, texts, key=key, model_sha=model_sha, gen_sha=gen_sha,
                         options=options, source_rel=source_rel,
                         command=_command(model.source_path, out_dir, model.build_options, methods, freeze),
                         methods=methods, glue="\n\n".join(glue_source(m) for m in methods),
                         why=selected)
    seconds = {"derive": derived - start, "emit": time.perf_counter() - derived}
    return GenerationParts(text, key, target, dyn, texts, seconds)


def generate_text(model, out_dir="generated", methods=None, freeze=None):
    """Return (module text, KEY, target path) for a loaded Model; nothing is written.

    methods: stepper methods to emit glue for (default all); only the kernels they reach are
    derived and emitted (codegen.needs). freeze: {parameter: value} folded into the kernels.
    """
    parts = generate_parts(model, out_dir, methods, freeze)
    return parts.text, parts.key, parts.target


def generate_model(model_path, out_dir="generated", methods=None, options=None,
                   freeze=None) -> GenerationResult:
    """Generate out_dir/<name>.py from a model file (atomic; unchanged files are not touched)."""
    model = load_model(model_path, **(options or {}))
    text, key, target = generate_text(model, out_dir, methods, freeze)
    written = write_if_changed(target, text)
    return GenerationResult(target, written, key)


def expected_key(model_path, out_dir="generated", methods=None, options=None, freeze=None):
    """(target path, KEY the model would get now) without deriving: for --check."""
    model = load_model(model_path, **(options or {}))
    opts = _options(model, _methods(methods), dict(sorted((freeze or {}).items())))
    key = make_key(model_hash(model.source_text), generator_hash(), opts)
    return output_path(model.name, out_dir), key


def is_current(model_path, out_dir="generated", methods=None, options=None, freeze=None):
    """(target, True when target exists and carries the KEY the model would get now)."""
    target, key = expected_key(model_path, out_dir, methods, options, freeze)
    return target, read_key(target) == key
