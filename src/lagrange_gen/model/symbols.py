"""The symbols of a model: the time t, generalized coordinates with their velocities, and
parameters with their defaults (a parameter's declaration and default are part of its identity,
so sympy's cache never hands one model another's)."""

from __future__ import annotations

import itertools
import keyword
import math

import sympy as sp

from ..errors import ModelError

__all__ = ["Coordinate", "Velocity", "Parameter", "coordinates", "parameters", "inputs", "t"]

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
    """(names, as_tuple): the names of a string (spaces or commas between them) or a sequence;
    as_tuple when a string ends in a comma, which asks for a tuple even of one name, as
    sympy.symbols does (``s, = coordinates("s,")``)."""
    if isinstance(names, str):
        return names.replace(",", " ").split(), names.rstrip().endswith(",")
    return list(names), False


def _shaped(symbols, as_tuple):
    """What a declaration returns: a tuple when asked (a trailing comma), else the symbol of a
    single name or the list of several."""
    if as_tuple:
        return tuple(symbols)
    return symbols[0] if len(symbols) == 1 else symbols


def coordinates(names):
    """Create generalized coordinates from a string of names, e.g. ``coordinates("x theta")``.

    Returns a list of :class:`Coordinate`, a single one when one name is given, or a tuple
    when the string ends in a comma (``s, = coordinates("s,")``, as sympy.symbols).
    """
    listed, as_tuple = _split_names(names)
    for n in listed:
        check_name("coordinate", n, where=f"coordinates({' '.join(listed)!r})")
    return _shaped([Coordinate(n) for n in listed], as_tuple)


def parameters(names, defaults=None):
    """Declare parameters, e.g. ``parameters("m l g", defaults=(1.0, 1.0, 9.81))``.

    ``defaults`` may be a sequence (same length), a dict by name, one number (the default of
    every name), or None (values required at simulation time); each default is a finite number
    or None. Every call declares new parameters (see :class:`Parameter`). Returns a list of
    :class:`Parameter`, a single one when one name is given, or a tuple when the string ends in
    a comma.
    """
    return declare(names, defaults, "parameters")


def inputs(names, defaults=None):
    """Declare control inputs, e.g. ``u = inputs("u")``: parameters that a Model lists in
    ``inputs=`` (the trailing slots of its parameter vector, written by the run loop from a
    controller or a signal before each step; see lagrange_gen.run.control). ``defaults`` as
    for parameters() (``inputs("tau1 tau2", defaults=0.0)``); without a default a run must
    supply the input."""
    return declare(names, defaults, "inputs")


def declare(names, defaults, function):
    """The parameters that ``function`` ("parameters" or "inputs", named in its messages)
    declares."""
    listed, as_tuple = _split_names(names)
    where = f"{function}({' '.join(listed)!r})"
    kind = "input" if function == "inputs" else "parameter"
    for n in listed:
        check_name(kind, n, where=where)
    params = [Parameter(n, next(_declarations), _finite_default(n, v, kind))
              for n, v in zip(listed, _default_values(listed, defaults, where))]
    return _shaped(params, as_tuple)


def _default_values(names, defaults, where):
    """One default (unchecked) per name from the forms parameters() accepts."""
    if defaults is None:
        return [None] * len(names)
    if isinstance(defaults, dict):
        unknown = sorted(set(map(str, defaults)) - set(names))
        if unknown:
            raise ModelError(f"{where}: defaults given for {', '.join(unknown)}, "
                             "which is not declared here")
        return [defaults.get(n) for n in names]
    if isinstance(defaults, (str, bytes)) or not hasattr(defaults, "__iter__"):
        return [defaults] * len(names)      # one default for every name
    values = list(defaults)
    if len(values) != len(names):
        raise ModelError(f"{where}: {len(names)} names but {len(values)} defaults")
    return values


def _finite_default(name, value, kind="parameter"):
    """``value`` as a float, or None; ModelError naming the parameter (or input) unless
    finite."""
    if value is None:
        return None
    try:
        number = float(value)
    except (TypeError, ValueError):
        number = math.nan
    if not math.isfinite(number):
        raise ModelError(f"{kind} {name}: default {value!r} is not a finite number "
                         "(give a finite number, or None for a value required at run time)")
    return number


def check_name(kind, name, where=None):
    """ModelError unless ``name`` is a Python identifier (``where``: the call that gave it)."""
    if not name.isidentifier() or keyword.iskeyword(name):
        prefix = f"{where}: " if where else ""
        raise ModelError(f"{prefix}{kind} name {name!r} is not a valid Python identifier")
