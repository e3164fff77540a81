"""Parameter vectors for generated modules: defaults, overrides by name, clear errors."""

from __future__ import annotations

import math

import numpy as np

from .errors import SimulationError


def resolve_params(names, defaults, given=None, model="model", frozen=None):
    """Return the parameter vector p (len(names),) float64.

    ``given``: None, a dict {name: value} overriding defaults, or a full sequence in PARAMS order.
    A parameter with no default and no given value, an unknown name or a non-finite value is a
    SimulationError naming it. ``frozen`` {name: value}: parameters folded into the generated
    kernels (module FROZEN); passing one is a SimulationError saying so.
    """
    names, values = list(names), [math.nan if d is None else float(d) for d in defaults]
    frozen = dict(frozen or {})
    if isinstance(given, dict):
        for key, value in given.items():
            if key in frozen:
                raise SimulationError(
                    f"{model}: parameter {key!r} is frozen at {frozen[key]!r} in this generated module "
                    f"(generated with --freeze); regenerate without freezing {key} to vary it")
            if key not in names:
                raise SimulationError(f"{model}: unknown parameter {key!r} (parameters: {', '.join(names) or 'none'})")
            values[names.index(key)] = float(value)
    elif given is not None:
        given = [float(v) for v in np.ravel(np.asarray(given, dtype=float))]
        if len(given) != len(names):
            note = f"; frozen, not passed: {', '.join(frozen)}" if frozen else ""
            raise SimulationError(f"{model}: {len(given)} parameter values given for {len(names)} "
                                  f"parameters ({', '.join(names)}){note}")
        values = given
    missing = [n for n, v in zip(names, values) if math.isnan(v)]
    if missing:
        raise SimulationError(f"{model}: parameter(s) {', '.join(missing)} have no value; pass them, "
                              f"e.g. params={{{missing[0]!r}: ...}} or --param {missing[0]}=...")
    bad = [f"{n}={v}" for n, v in zip(names, values) if not math.isfinite(v)]
    if bad:
        raise SimulationError(f"{model}: non-finite parameter value(s) {', '.join(bad)}")
    return np.array(values, dtype=np.float64)
