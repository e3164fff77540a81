"""Import generated modules by path, generating them first when given a model file."""

from __future__ import annotations

import hashlib
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
    # The name must be the same in every process: numba's cache refers to globals by module name.
    name = f"lagrange_gen_generated_{hashlib.sha1(str(path).encode()).hexdigest()[:12]}_{path.stem}"
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
    from .keys import read_key
    path = Path(path)
    if read_key(path) is not None:
        return import_generated(path)
    target, current = is_current(path, out_dir, methods, options)
    if not current:
        if not regenerate:
            raise StaleModuleError(f"{target} is missing or stale: run lagrange-gen {path}")
        target = generate_model(path, out_dir, methods, options).path
    return import_generated(target)


def _kernel_args(module):
    """{kernel name: arguments of a call on zeros} for every kernel a module may have."""
    import numpy as np
    n, m, ne = module.N_COORDS, module.N_CONSTRAINTS, module.N_ELEMENTS
    q, w, lam, we = np.zeros(n), np.zeros(n), np.zeros(m), np.zeros(ne)
    p = np.ones(module.N_PARAMS)
    A, B, v = np.empty((n, n)), np.empty((n, n)), np.empty(n)
    return {
        "mass_matrix": (q, p, A), "dynamics": (q, q, 0.0, p, A, v), "rhs": (q, q, 0.0, p, v),
        "energy": (q, q, 0.0, p), "momentum_rate": (q, q, 0.0, p, v),
        "rhs_jacobian": (q, q, 0.0, p, A, B), "momentum_rate_jacobian": (q, q, 0.0, p, A, B),
        "mass_matvec_dq": (q, w, p, A),
        "constraints": (q, q, p, np.empty(m), np.empty((m, n)), np.empty(m)),
        "constraint_dq": (q, w, lam, p, np.empty((m, n)), A),
        "elements": (q, p, np.empty(ne), np.empty((ne, n)), np.empty((ne, 3))),
        "elements_hessian": (q, we, p, A),
        "forward_dynamics": (q, q, 0.0, p, A, v),
    }


def compile_all(module):
    """Call every kernel a generated module has (its KERNELS, plus forward_dynamics) once on
    zeros so numba compiles (or loads from its cache) all of them now rather than inside the
    first simulation step. Kernels a module was generated without are skipped."""
    args = _kernel_args(module)
    for name in tuple(getattr(module, "KERNELS", ())) + ("forward_dynamics",):
        if name not in args:
            raise GenerationError(f"{module.__file__}: unknown kernel {name!r} (regenerate it)")
        getattr(module, name)(*args[name])
