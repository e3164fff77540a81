"""Turning what a model file gives into checked scalar sympy expressions: dynamicsymbols
converted to Coordinates, sympify with one-line errors, the Rayleigh-function check, and the
events g(q, qdot, t) (Event) whose zero crossings simulate locates."""

from __future__ import annotations

import sympy as sp

from ..errors import ModelError
from .symbols import Coordinate, Parameter, Velocity, check_name, t


def _is_dynamicsymbol(c):
    return (isinstance(c, sp.core.function.AppliedUndef) and len(c.args) == 1
            and isinstance(c.args[0], sp.Symbol))


def mechanics_speeds(coords):
    """[q(t)' for q(t) in coords] when every coordinate is a dynamicsymbol (the speeds that
    sympy.physics.mechanics loads are converted with), else []."""
    if not all(_is_dynamicsymbol(c) for c in coords):
        return []
    return [sp.Derivative(c, c.args[0]) for c in coords]


def is_mechanics_load(item):
    """A sympy.physics.mechanics load (lagrange_gen.model.mechanics.is_mechanics_load), cheaply False
    for anything that cannot be one (no mechanics import)."""
    from .loads import PointForce
    if not (isinstance(item, tuple) or isinstance(item, PointForce)):
        return False
    from .mechanics import is_mechanics_load as check
    return check(item)


def equation_as_expr(c):
    """An sp.Eq(lhs, rhs) constraint as lhs - rhs (Phi = 0 means lhs = rhs); others unchanged."""
    return c.lhs - c.rhs if isinstance(c, sp.Equality) else c


def unknown_symbols_hint(unknown):
    """A hint for symbols that are not part of the model: plain sp.Symbols are not parameters
    (their defaults and order come from lagrange_gen.parameters); '' when none is plain."""
    plain = sorted(str(s) for s in unknown if type(s) is sp.Symbol)
    if not plain:
        return ""
    names = " ".join(plain)
    return (f"; plain sp.symbols are not parameters: declare them with "
            f"lagrange_gen.parameters({names!r}, defaults=...) (or coordinates() if they move)")


def convert_dynamicsymbols(coords):
    """Turn sympy.physics.mechanics dynamicsymbols q(t) into Coordinates.

    Returns (coordinates, replacement map) where the map sends q(t)' -> q.d, q(t) -> q and the
    mechanics time symbol to our t.
    """
    replace = {}
    out = []
    for c in coords:
        if isinstance(c, Coordinate):
            out.append(c)
            continue
        if _is_dynamicsymbol(c):
            time_sym = c.args[0]
            coord = Coordinate(str(c.func))
            replace[sp.Derivative(c, time_sym)] = coord.d
            replace[c] = coord
            replace[time_sym] = t
            out.append(coord)
            continue
        hint = (f" (declare it with lagrange_gen.coordinates({str(c)!r}), or as a "
                "sympy.physics.mechanics dynamicsymbol)" if isinstance(c, sp.Symbol) else "")
        raise ModelError(f"coordinate {c!r} is neither a Coordinate nor a dynamicsymbol q(t){hint}")
    if replace:
        # Derivatives must be replaced before the functions they contain.
        derivs = {k: v for k, v in replace.items() if isinstance(k, sp.Derivative)}
        rest = {k: v for k, v in replace.items() if not isinstance(k, sp.Derivative)}
        return out, _ChainedReplace(derivs, rest)
    return out, {}


class _ChainedReplace(dict):
    """A replacement applied in two passes (derivatives, then functions and time)."""

    def __init__(self, first, second):
        super().__init__({**first, **second})
        self.first, self.second = first, second


def _apply(expr, replace):
    if isinstance(replace, _ChainedReplace):
        return expr.xreplace(replace.first).xreplace(replace.second)
    return expr.xreplace(replace)


def sympify_scalar(expr, what, replace):
    """``expr`` as a scalar sympy Expr with ``replace`` applied; ModelError naming ``what``."""
    try:
        expr = sp.sympify(expr)
    except (sp.SympifyError, TypeError) as exc:
        raise ModelError(f"{what} is not a SymPy expression: {exc}") from None
    if getattr(expr, "is_Matrix", False):       # sympy matrices are Expr too
        rows, cols = expr.shape
        raise ModelError(f"{what} is a {rows} x {cols} matrix, not a scalar expression "
                         "(take its entry, e.g. T[0], or sum the terms)")
    if not isinstance(expr, sp.Expr):
        raise ModelError(f"{what} is not a scalar SymPy expression: {expr!r}")
    return _apply(expr, replace) if replace else expr


def check_rayleigh(name, D, velocities):
    """ModelError naming the first term of the dissipation function D that gives a wrong or no
    force: D and its velocity gradient must vanish at rest (D quadratic in the velocities, or of
    higher degree such as c |v|^3 / 3). A velocity-free term gives no force -dD/dqdot at all; a
    term linear near rest (c x v, c |v|, sin v) gives a force that does not vanish at rest."""
    if D == 0 or _rayleigh_problem(D, velocities) is None:
        return
    for terms in (sp.Add.make_args(D), sp.Add.make_args(sp.expand(D))):
        for term in terms:
            why = _rayleigh_problem(term, velocities)
            if why:
                raise ModelError(f"model {name}: dissipation term {term} {why}")
    raise ModelError(f"model {name}: dissipation {D} {_rayleigh_problem(D, velocities)}")


def _rayleigh_problem(D, velocities):
    """Why D is not a Rayleigh function (a phrase), or None. With every velocity scaled by
    s > 0, D and its velocity gradient must vanish as s -> 0 (s positive lets sign(s v) and
    |s v| simplify, so that c |v| is seen as linear although its gradient is 0 at v = 0)."""
    if not (D.free_symbols & set(velocities)):
        return ("does not depend on any velocity: it gives no force -dD/dqdot (a potential "
                "belongs in V)")
    s = sp.Dummy("s", positive=True)
    scaled = {v: s * v for v in velocities}
    if not _vanishes_at_rest(D.xreplace(scaled), s):
        return ("is not zero at rest (a Rayleigh function is quadratic in the velocities, "
                "e.g. c*x.d**2/2)")
    if not all(_vanishes_at_rest(D.diff(v).xreplace(scaled), s) for v in velocities):
        return ("is linear in the velocities near rest, so its force -dD/dqdot does not vanish at "
                "rest: a Rayleigh function is quadratic in the velocities (e.g. c*x.d**2/2); dry "
                "friction is DryFriction, other forces go in forces=")
    return None


#: sympy's numbers that no kernel can compute, and what makes them.
NONFINITE = {sp.zoo: "complex infinity, e.g. from a division by zero such as x/0, or log(0)",
             sp.oo: "infinity", -sp.oo: "minus infinity", sp.nan: "not a number, e.g. 0*oo"}


def nonfinite_term(expr):
    """(term, atom) of the first of sympy's zoo, oo, -oo, nan found in ``expr``: term is the
    summand of ``expr`` that holds it (``expr`` itself when it is no sum); None when there is
    none."""
    has = getattr(expr, "has", None)
    if has is None:
        return None
    for atom in NONFINITE:
        if has(atom):
            terms = expr.args if expr.is_Add else (expr,)
            return next(t for t in terms if t.has(atom)), atom
    return None


def nonfinite_message(where, expr):
    """'V = zoo*x: the term zoo*x holds zoo (complex infinity, ...); ...' for an expression that
    holds a non-finite number (nonfinite_term), else None."""
    found = nonfinite_term(expr)
    if found is None:
        return None
    term, atom = found
    text = str(expr)
    shown = f"{where} = {text}" if len(text) <= 100 else where
    return (f"{shown}: the term {term} holds {atom} ({NONFINITE[atom]}); the kernels would "
            f"compute NaN: every expression of a model must be finite")


def _vanishes_at_rest(expr, s):
    value = expr.subs(s, 0)
    if value.has(sp.nan, sp.zoo, sp.oo, -sp.oo):
        value = sp.limit(expr, s, 0, "+")
    return value == 0 or sp.simplify(value) == 0


class Event:
    """An event function g(q, qdot, t) of a model (``Model(events={name: expr or Event})``):
    simulate locates the times where g crosses zero inside a step and records (time, state,
    which event, direction).

    ``direction``: +1 records only rising crossings (g from negative to >= 0 in the order of
    integration), -1 only falling ones (g from positive to <= 0), 0 both. ``terminal``: the run
    stops at the first recorded crossing (the final state is the state at the event).
    """

    def __init__(self, expr, terminal=False, direction=0):
        # Checked by the Model (named_events), whose messages name the model and the event.
        self.expr, self.terminal, self.direction = expr, terminal, direction
        self.name = None        # the key of the events dict (set by Model)

    def __repr__(self):
        return (f"Event({self.name or ''}: {self.expr}, terminal={self.terminal}, "
                f"direction={self.direction!r})")


def named_events(model_name, events, replace):
    """``events`` {name: expression or Event} as a list of named Events with scalar sympy
    expressions (``replace`` applied); ModelError naming the model and the event."""
    if events is None:
        return []
    if not isinstance(events, dict):
        raise ModelError(f"model {model_name}: events must be a dict {{name: expression or "
                         f"Event(expression, terminal=, direction=)}}, got {events!r}")
    out = []
    for name, given in events.items():
        if not isinstance(name, str):
            raise ModelError(f"model {model_name}: event name {name!r} is not a string")
        check_name("event", name)
        event = given if isinstance(given, Event) else Event(given)
        terminal, direction = event.terminal, event.direction
        if not isinstance(terminal, (bool, int)) or terminal not in (0, 1):
            raise ModelError(f"model {model_name}: event {name}: terminal must be True or False, "
                             f"got {terminal!r}")
        if isinstance(direction, bool) or direction not in (-1, 0, 1):
            raise ModelError(f"model {model_name}: event {name}: direction must be +1 (rising), "
                             f"-1 (falling) or 0 (both), got {direction!r}")
        try:
            expr = sympify_scalar(event.expr, f"event {name}", replace)
        except ModelError as exc:
            raise ModelError(f"model {model_name}: {exc}") from None
        if not expr.free_symbols:
            raise ModelError(f"model {model_name}: event {name} is the constant {expr}: it never "
                             f"crosses zero (an event function must depend on q, qdot or t)")
        named = Event(expr, bool(terminal), int(direction))
        named.name = name
        out.append(named)
    return out


def prescriptions(model_name, prescribed, coords, replace):
    """``prescribed`` {Coordinate: expression of t and parameters} checked: {Coordinate: sympy
    expression}. ModelError (one line naming the symbol) for a key that is not a Coordinate or
    is also in coords, and for an expression using a coordinate, a velocity or another symbol."""
    if prescribed is None:
        return {}
    if not isinstance(prescribed, dict):
        raise ModelError(f"model {model_name}: prescribed must be a dict {{coordinate: expression of t}}, "
                         f"got {prescribed!r}")
    out = {}
    for c, given in prescribed.items():
        c = replace.get(c, c) if replace else c
        if not isinstance(c, Coordinate):
            raise ModelError(f"model {model_name}: prescribed key {c!r} is not a Coordinate "
                             "(declare it with coordinates() and leave it out of coords)")
        if c in coords:
            raise ModelError(f"model {model_name}: prescribed coordinate {c} is also in coords; "
                             "a coordinate is either free (coords) or prescribed, not both")
        try:
            expr = sympify_scalar(given, f"prescription of {c}", replace)
        except ModelError as exc:
            raise ModelError(f"model {model_name}: {exc}") from None
        for s in sorted(expr.free_symbols, key=str):
            if isinstance(s, Velocity):
                raise ModelError(f"model {model_name}: prescription of {c} uses the velocity {s}; "
                                 "a prescribed coordinate is a function of t and parameters only")
            if isinstance(s, Coordinate):
                raise ModelError(f"model {model_name}: prescription of {c} uses the coordinate {s}; "
                                 "a prescribed coordinate is a function of t and parameters only "
                                 "(a relation between coordinates is a constraint)")
            if not (isinstance(s, Parameter) or s == t):
                raise ModelError(f"model {model_name}: prescription of {c} uses the symbol {s}, which "
                                 "is neither a parameter nor t")
        if expr.has(sp.Derivative) or expr.atoms(sp.core.function.AppliedUndef):
            raise ModelError(f"model {model_name}: prescription of {c} contains an undefined function "
                             f"or derivative: {expr}")
        out[c] = expr
    return out


#: Functions constant between their jumps, whose derivative is 0 where it exists
#: (derive/kinks.py sets it so; a model may contain it, e.g. from a point force's virtual work).
PIECEWISE_CONSTANT = (sp.floor, sp.ceiling, sp.sign, sp.Heaviside)


def zero_derivative(expr) -> bool:
    """Whether the unevaluated ``Derivative`` ``expr`` is one of a piecewise-constant function."""
    return isinstance(expr, sp.Derivative) and isinstance(expr.expr, PIECEWISE_CONSTANT)


def settled_later(derivative) -> bool:
    """Whether derive/kinks.py closes the unevaluated ``derivative``: a piecewise-constant
    function's (0), or frac's and Mod's (through floor)."""
    return zero_derivative(derivative) or isinstance(derivative.expr, (sp.frac, sp.Mod))
