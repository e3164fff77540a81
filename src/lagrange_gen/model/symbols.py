"""The symbols of a model: the time t, generalized coordinates with their velocities, and
parameters with their defaults (a parameter's declaration and default are part of its identity,
so sympy's cache never hands one model another's)."""

from __future__ import annotations

import itertools
import keyword
import math

import sympy as sp

from ..errors import ModelError

__all__ = ["Coordinate", "Velocity", "Parameter", "coordinates", "parameters", "t"]

#: The time symbol. Forces and potentials may depend on it; T and constraints may not.
t = sp.Symbol("t", real=True)

# Serial numbers of parameter declarations (0: a Parameter made directly, never declared).
_declarations = itertools.count(1)


class Coordinate(sp.Symbol):
    """A generalized coordinate. ``.d`` is its velocity symbol (named ``<name>_dot``)."""

    def __new__(cls, name):
        return super().__new__(cls, name, real=True)

    @property
    def d(self) -> "Velocity":
        return Velocity(self.name + "_dot")


class Velocity(sp.Symbol):
    """The time derivative of a :class:`Coordinate`."""

    def __new__(cls, name):
        return super().__new__(cls, name, real=True)


class Parameter(sp.Symbol):
    """A model parameter, declared by :func:`parameters`: ``default`` (float or None) and
    ``declaration`` (serial number; Models list their parameters in declaration order).

    The declaration is part of the symbol's identity (and the default belongs to it). sympy
    caches symbols and expressions by equality, so what a symbol carries must take part in
    equality: two declarations of ``m`` (two model files, two parameters() calls) are two
    different symbols that print alike, and the cache can never hand one model another's default
    or position. No table outside the symbols: a model's PARAMS depend on its own declarations
    only, not on what else the process declared.
    """

    __slots__ = ("declaration", "default")

    def __new__(cls, name, declaration=0, default=None):
        obj = sp.Symbol.__xnew__(cls, name, real=True)      # not the cached constructor: see above
        obj.declaration, obj.default = declaration, default
        return obj

    def __getnewargs_ex__(self):
        return ((self.name, self.declaration, self.default), {})

    def _hashable_content(self):
        return super()._hashable_content() + (self.declaration,)


def _split_names(names):
    if isinstance(names, str):
        names = names.replace(",", " ").split()
    return list(names)


def coordinates(names):
    """Create generalized coordinates from a space-separated string, e.g. ``coordinates("x theta")``.

    Returns a list of :class:`Coordinate` (a single one when one name is given).
    """
    coords = [Coordinate(n) for n in _split_names(names)]
    return coords[0] if len(coords) == 1 else coords


def parameters(names, defaults=None):
    """Declare parameters, e.g. ``parameters("m l g", defaults=(1.0, 1.0, 9.81))``.

    ``defaults`` may be a sequence (same length), a dict by name, a number (one name), or None
    (values required at simulation time); each default is a finite number or None. Every call
    declares new parameters (see :class:`Parameter`). Returns a list of :class:`Parameter` (a
    single one when one name is given).
    """
    names = _split_names(names)
    for n in names:
        check_name("parameter", n)
    params = [Parameter(n, next(_declarations), _finite_default(n, v))
              for n, v in zip(names, _default_values(names, defaults))]
    return params[0] if len(params) == 1 else params


def _default_values(names, defaults):
    """One default (unchecked) per name from the forms parameters() accepts."""
    listed = " ".join(names)
    if defaults is None:
        return [None] * len(names)
    if isinstance(defaults, dict):
        unknown = sorted(set(map(str, defaults)) - set(names))
        if unknown:
            raise ModelError(f"parameters({listed!r}): defaults given for {', '.join(unknown)}, "
                             "which is not declared here")
        return [defaults.get(n) for n in names]
    if isinstance(defaults, (str, bytes)) or not hasattr(defaults, "__iter__"):
        if len(names) == 1:
            return [defaults]
        raise ModelError(f"parameters({listed!r}): defaults must be a sequence of {len(names)} "
                         f"numbers, a dict by name or None, got {defaults!r}")
    values = list(defaults)
    if len(values) != len(names):
        raise ModelError(f"parameters({listed!r}): {len(names)} names but {len(values)} defaults")
    return values


def _finite_default(name, value):
    """``value`` as a float, or None; ModelError naming the parameter unless finite."""
    if value is None:
        return None
    try:
        number = float(value)
    except (TypeError, ValueError):
        number = math.nan
    if not math.isfinite(number):
        raise ModelError(f"parameter {name}: default {value!r} is not a finite number "
                         "(give a finite number, or None for a value required at run time)")
    return number


def check_name(kind, name):
    if not name.isidentifier() or keyword.iskeyword(name):
        raise ModelError(f"{kind} name {name!r} is not a valid Python identifier")
