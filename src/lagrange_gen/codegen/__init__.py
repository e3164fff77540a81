"""Code generation stage: Dynamics -> KernelSpecs -> text -> generated/<name>.py, and freshness.

The pipeline (generate; the file on disk: generated_files), kernel specs (spec), CSE, the printer, rendering, the glue templates
(glue) and the atomic write live here, and so does what decides whether a generated module is
current: KEY and the stale check (keys), the package files compiled code is built from
(sources). keys and sources are imported by generated modules and by the jit layer at run
time, so this package's ``__init__`` imports nothing: the pipeline names below load sympy on
first use. codegen may import derive, model, errors and (for the method list and the stepper
sources it reads) steppers.core.registry, never run/, cli/ or viz/.
"""

from importlib import import_module

_LAZY = {"generate_model": "generated_files", "generate_text": "generate", "output_path": "generate",
         "read_key": "keys", "KernelSpec": "spec", "make_kernels": "compose"}

__all__ = sorted(_LAZY)


def __getattr__(name):
    if name in _LAZY:
        return getattr(import_module(f".{_LAZY[name]}", __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
