"""Parameter vectors for generated modules: defaults, overrides by name, clear errors."""

from __future__ import annotations

import math

import numpy as np

from ..errors import SimulationError


def resolve_params(names, defaults, given=None, model="model", frozen=None):
    """Return the parameter vector p (len(names),) float64.

    ``given``: None, a dict {name: value} overriding defaults, or a full sequence in PARAMS order.
    A parameter with no default and no given value, an unknown name, or a given value that is not
    a finite number (NaN, inf, 'abc', True) is a SimulationError naming it. ``frozen``
    {name: value}: parameters folded into the generated kernels (module FROZEN); passing one is a
    SimulationError saying so.
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
            values[names.index(key)] = _finite(model, key, value)
    elif given is not None:
        given = _sequence(model, names, given, frozen)
        values = [_finite(model, name, value) for name, value in zip(names, given)]
    missing = [n for n, v in zip(names, values) if math.isnan(v)]
    if missing:
        raise SimulationError(f"{model}: parameter(s) {', '.join(missing)} have no value; pass them, "
                              f"e.g. params={{{missing[0]!r}: ...}} or --param {missing[0]}=...")
    return np.array(values, dtype=np.float64)


def is_number(value):
    """A real number that is not a bool (h=True must not run with h = 1)."""
    if type(value) is float or type(value) is int:      # the common case, first (bool is not int)
        return True
    return isinstance(value, (int, float, np.floating, np.integer)) and not isinstance(
        value, (bool, np.bool_))


def _finite(model, name, value):
    """float(value), or a SimulationError naming the parameter when it is not a finite number."""
    number = is_number(value)
    if not number or not math.isfinite(value):
        what = "not finite" if number else "not a number"
        raise SimulationError(f"{model}: parameter {name!r} = {value!r} is {what}; give a finite "
                              f"number")
    return float(value)


def _sequence(model, names, given, frozen):
    """A full parameter sequence in PARAMS order as a list, or a SimulationError."""
    try:
        seq = list(np.ravel(np.asarray(given, dtype=object)))
    except (TypeError, ValueError):
        seq = None
    if seq is None or len(seq) != len(names):
        count = "?" if seq is None else len(seq)
        note = f"; frozen, not passed: {', '.join(frozen)}" if frozen else ""
        raise SimulationError(f"{model}: {count} parameter values given for {len(names)} "
                              f"parameters ({', '.join(names)}){note}; pass a dict {{name: value}} "
                              f"or one number per parameter")
    return seq
