"""Import generated modules by path, generating them first when given a model file; the
self-registration every generated module runs at import (its numba decorator is
lagrange_gen.jit.njit)."""

from __future__ import annotations

import hashlib
import sys
from pathlib import Path

from ..codegen.keys import check_current, default_generated_dir, read_key
from ..errors import GenerationError, StaleModuleError
from ..codegen import model_cache
from ..jit.cache import GENERATED_MODULE_PREFIX
from ..jit.folders import import_file


def import_generated(path):
    """Import a generated module from its file path; the same path imported twice returns the
    same module object. Raises StaleModuleError (from the module's own check) when stale."""
    path = Path(path).resolve()
    if not path.is_file():
        raise GenerationError(f"{path}: no generated module here (run lagrange-gen on its model)")
    # The name must be the same in every process: numba's cache refers to globals by module name.
    name = f"{GENERATED_MODULE_PREFIX}{hashlib.sha1(str(path).encode()).hexdigest()[:12]}_{path.stem}"
    cached = sys.modules.get(name)
    # The file may have been regenerated since this process imported it: then import it again;
    # otherwise the module's own import-time check runs again (its model may have changed).
    if cached is not None and getattr(cached, "KEY", None) == read_key(path):
        if hasattr(cached, "SOURCES"):
            check_current(cached.__file__, cached.KEY, cached.SOURCES, cached.MODEL_PATH,
                          cached.OPTIONS, cached.TEXT_SHA)
        return cached
    return import_file(name, path)


def load(path, out_dir=None, methods=None, options=None, regenerate=True, freeze=None,
         force=False, sensitivities=False):
    """Return the generated module for ``path``.

    ``path`` is a generated module (it has a KEY line) or a model file. For a model file the
    module already in ``out_dir`` is used when it is current and satisfies the request: it has
    the ``methods`` (None: any), the ``freeze`` (None: whatever it was generated with, e.g. by
    ``lagrange-gen --freeze``) and the build ``options`` (None: likewise). Otherwise it is
    generated: when missing, when stale (keeping its own freeze, build and methods unless asked
    otherwise), or when methods are missing (added to its own). A current module generated with
    another freeze or build, or from another model file, is refused in one line naming what
    differs and the command that regenerates it (``force=True`` regenerates it);
    ``regenerate=False`` raises StaleModuleError instead of generating. ``out_dir`` None: the
    model's own place, the same from any working directory (codegen.keys.default_generated_dir).
    ``sensitivities``: the module must have the parameter derivatives of forward sensitivities
    (regenerated with them, keeping everything else, when it lacks them).
    """
    path = Path(path)
    if read_key(path) is not None:
        return import_generated(path)
    if out_dir is None:
        out_dir = default_generated_dir(path)
    # a module this file gave before, current and complete: import it without running the file
    known = None if force else model_cache.current_module(path, out_dir, methods, options, freeze,
                                                          sensitivities)
    if known is not None:
        return import_generated(known)
    from ..codegen.generated_files import generate_model
    target, plan, model = _plan(path, out_dir, methods, options, freeze, force, sensitivities)
    if plan is not None:
        why, build, methods, freeze, command, sensitivities = plan
        if not regenerate:
            raise StaleModuleError(f"{target} is {why}: run {command}")
        generate_model(path, out_dir, methods, build, freeze, force=True, model=model,
                       sensitivities=sensitivities)
    module = import_generated(target)
    model_cache.remember_module(path, out_dir, options, target)
    return module


def _plan(path, out_dir, methods, options, freeze, force, sensitivities=False):
    """(target, None, model) when the module on disk serves the request of load(), else (target,
    (why, build, methods, freeze, command, sensitivities), model) to generate with; model: the Model the
    model file's last run gave when its build is the one to generate (generation then does not
    run the file again), else None. Requested methods that do not
    apply to the model are not added (simulate refuses them, naming why); whether the module
    on disk is current is codegen.generated_files.module_current (re-derives only when the model file
    or the generator changed since that was last decided)."""
    from ..codegen.generate import generation_options, output_path, resolve_methods
    from ..codegen.generated_files import describe_options, module_current, other_source, refuse_overwrite
    from ..codegen.keys import read_header, regeneration_command
    from ..model.model_file import load_model
    model = load_model(path, **(options or {}))
    target = output_path(model.name, out_dir)
    header = read_header(target) or {}
    if not force:
        refuse_overwrite(path, target, model.name)
    disk = header.get("OPTIONS") if other_source(path, target, header) is None else None
    asked = resolve_methods(methods, model, drop_inapplicable=True) if methods else None
    if not isinstance(disk, dict):          # missing (or forced over another model's module)
        build, freeze = dict(options or {}), dict(freeze or {})
        methods = resolve_methods(asked or None, model)
        command = regeneration_command(path, out_dir, build, methods, freeze, sensitivities)
        return target, ("missing", build, methods, freeze, command, sensitivities), model
    have = list(disk.get("methods", ()))
    build = dict(disk.get("build", {}) if options is None else options)
    freeze = dict(disk.get("freeze", {}) if freeze is None else freeze)
    if disk.get("build", {}) != model.build_options:
        model = load_model(path, **disk.get("build", {}))   # the module's own build, to compare
    # the Model of the build to generate when the last run of the file gave it (the file is not
    # run again; what it read is recorded as that run found it)
    model_for_build = model if model.build_options == build else None
    methods = resolve_methods(have + list(asked or ()), model, drop_inapplicable=True)
    sensitivities = bool(sensitivities or disk.get("sensitivities", False))
    wanted = generation_options(build, methods, freeze, sensitivities)
    command = regeneration_command(path, out_dir, build, methods, freeze, sensitivities)
    if not module_current(model, target, header):
        return target, ("stale", build, methods, freeze, command, sensitivities), model_for_build
    if (wanted["build"], wanted.get("freeze")) != (disk.get("build"), disk.get("freeze")) and not force:
        have_options = {"build": disk.get("build"), "freeze": disk.get("freeze")}
        raise GenerationError(f"{target} was generated with {describe_options(have_options)}, not with "
                              f"{describe_options(wanted | {'methods': None})} as asked: regenerate it "
                              f"with `{command}`, or ask for what it has")
    if wanted != disk:
        missing = [m for m in methods if m not in have]
        why = (f"missing method(s) {', '.join(missing)}" if missing else
               "without the parameter derivatives of sensitivities")
        return target, (why, build, methods, freeze, command, sensitivities), model_for_build
    return target, None, model_for_build


def register_module(namespace):
    """Make ``sys.modules[namespace['__name__']]`` the module whose globals are ``namespace``.

    Every generated module calls this on import: its stepper glue finds the module in
    sys.modules, and numba's cache re-imports it by name. Imports through the import system
    or import_generated have done it already; importlib's spec_from_file_location +
    exec_module by hand has not.
    """
    name = namespace["__name__"]
    current = sys.modules.get(name)
    if current is not None and getattr(current, "__dict__", None) is namespace:
        return
    import gc
    import types
    for owner in gc.get_referrers(namespace):
        if isinstance(owner, types.ModuleType) and owner.__dict__ is namespace:
            sys.modules[name] = owner
            return


def kernel_call_args(module):
    """{kernel name: arguments of a call on zeros} for every kernel a module may have."""
    import numpy as np
    n, m, ne = module.N_COORDS, module.N_CONSTRAINTS, module.N_ELEMENTS
    nc = getattr(module, "N_CONTACTS", 0)
    nr = getattr(module, "N_NONHOLONOMIC", 0)
    q, w, lam, we = np.zeros(n), np.zeros(n), np.zeros(m), np.zeros(ne)
    p = np.ones(module.N_PARAMS)
    A, B, v = np.empty((n, n)), np.empty((n, n)), np.empty(n)
    return {
        "mass_matrix": (q, 0.0, p, A), "dynamics": (q, q, 0.0, p, A, v), "rhs": (q, q, 0.0, p, v),
        "energy": (q, q, 0.0, p), "momentum_rate": (q, q, 0.0, p, v),
        "rhs_jacobian": (q, q, 0.0, p, A, B), "momentum_rate_jacobian": (q, q, 0.0, p, A, B),
        "mass_matvec_dq": (q, w, 0.0, p, A),
        "constraints": (q, q, 0.0, p, np.empty(m), np.empty((m, n)), np.empty(m)),
        "constraint_rate": (q, 0.0, p, np.empty(m)),
        "transport": (q, 0.0, p, v), "power": (q, q, 0.0, p, np.empty(2 * n + 2)), "transport_dq": (q, 0.0, p, A),
        "constraint_dq": (q, w, lam, 0.0, p, np.empty((m, n)), A),
        "elements": (q, p, np.empty(ne), np.empty((ne, n)), np.empty((ne, 3))),
        "elements_hessian": (q, we, p, A),
        "contacts": (q, 0.0, p, np.empty(nc), np.empty((nc, n)), np.empty((2 * nc, n)),
                     np.empty((nc, 2))),
        "contact_bias": (q, 0.0, p, np.empty(3 * nc)),
        "contact_rates": (q, q, 0.0, p, np.empty(3 * nc)),
        "nonholonomic": (q, q, 0.0, p, np.empty((nr, n)), np.empty(nr), np.empty(nr)),
        "nonholonomic_dq": (q, q, w, np.zeros(nr), 0.0, p, np.empty((nr, n)), B,
                            np.empty((nr, n)), np.empty((nr, n)), np.empty((nr, n))),
        "constraint_gamma_dq": (q, q, 0.0, p, np.empty((m, n)), np.empty((m, n))),
        "forward_dynamics": (q, q, 0.0, p, A, v),
        "events": (q, q, 0.0, p, np.empty(getattr(module, "N_EVENTS", 0))),
        "inverse_dynamics": (q, q, q, 0.0, p, v), "gravity_forces": (q, 0.0, p, v),
        "bias_forces": (q, q, 0.0, p, v),
    }


def compile_all(module):
    """Call every kernel a generated module has (its KERNELS, plus forward_dynamics) once on
    zeros so numba compiles (or loads from its cache) all of them now rather than inside the
    first simulation step. Kernels a module was generated without are skipped."""
    args = kernel_call_args(module)
    for name in tuple(getattr(module, "KERNELS", ())) + ("forward_dynamics",):
        if name not in args:
            raise GenerationError(f"{module.__file__}: unknown kernel {name!r} (regenerate it)")
        getattr(module, name)(*args[name])
