"""Import generated modules by path, generating them first when given a model file."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

from .errors import GenerationError, StaleModuleError


def import_generated(path):
    """Import a generated module from its file path; the same path imported twice returns the
    same module object. Raises StaleModuleError (from the module's own check) when stale."""
    path = Path(path).resolve()
    if not path.is_file():
        raise GenerationError(f"{path}: no generated module here (run lagrange-gen on its model)")
    name = f"lagrange_gen_generated_{abs(hash(str(path))):x}_{path.stem}"
    if name in sys.modules:
        return sys.modules[name]
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    try:
        spec.loader.exec_module(module)
    except BaseException:
        del sys.modules[name]
        raise
    return module


def load(path, out_dir="generated", methods=None, options=None, regenerate=True):
    """Return the generated module for ``path``.

    ``path`` is a generated module (it has a KEY line) or a model file; a model file is generated
    into ``out_dir`` first when its module is missing or stale (``regenerate=False``: raise instead).
    """
    from .codegen.generate import generate_model, is_current
    from .codegen.key import read_key
    path = Path(path)
    if read_key(path) is not None:
        return import_generated(path)
    target, current = is_current(path, out_dir, methods, options)
    if not current:
        if not regenerate:
            raise StaleModuleError(f"{target} is missing or stale: run lagrange-gen {path}")
        target = generate_model(path, out_dir, methods, options).path
    return import_generated(target)
