"""The user-facing model: coordinates, parameters, energies, forces and constraints.

A model file under ``models/`` builds a :class:`Model` from SymPy expressions and assigns it to a
variable named ``model`` (optionally it also defines ``build(**options)`` returning a Model, for
families such as the n-link pendulum). :func:`lagrange_gen.model_file.load_model` executes such
a file; Model validates what it is given.
"""

from __future__ import annotations

import itertools
import keyword
import math
from dataclasses import dataclass

import sympy as sp

from .errors import ModelError

__all__ = [
    "Coordinate", "Velocity", "Parameter", "PointForce", "SaintVenant", "DryFriction", "Model",
    "coordinates", "parameters", "t",
]

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


@dataclass(frozen=True)
class PointForce:
    """A force applied at a point; its generalized force follows from virtual work.

    ``point``: position of the application point, 2 or 3 expressions in q (and t).
    ``force``: the force vector, same length, expressions in q, qdot and t.
    Q_j = sum_k force_k * d point_k / d q_j.
    """

    point: tuple
    force: tuple

    def __init__(self, point, force):
        point = tuple(sp.sympify(e) for e in point)
        force = tuple(sp.sympify(e) for e in force)
        if len(point) != len(force):
            raise ModelError(f"PointForce: point has {len(point)} components, force has {len(force)}")
        object.__setattr__(self, "point", point)
        object.__setattr__(self, "force", force)


class SaintVenant:
    """A Saint-Venant element: a spring of stiffness k in series with a slider of threshold eta,
    acting on the strain s(q).

    Its internal variable u (the elastic part of s) obeys u' + dpsi_[-eta, eta](u) ∋ s', and it
    exerts the generalized force -k u grad s(q). Give ``threshold`` (eta) or ``yield_force``
    (alpha = k eta). Several elements form the generalized Prandtl model; a parallel spring in V
    gives linear hardening, a dashpot in ``dissipation`` the viscoelastoplastic model.
    """

    kind = "saint_venant"

    def __init__(self, strain, stiffness, threshold=None, yield_force=None, name=None):
        if (threshold is None) == (yield_force is None):
            raise ModelError("SaintVenant: give exactly one of threshold (eta) or yield_force (alpha = k eta)")
        self.strain = sp.sympify(strain)
        self.stiffness = sp.sympify(stiffness)
        self.threshold = (sp.sympify(threshold) if threshold is not None
                          else sp.sympify(yield_force) / self.stiffness)
        self.name = name

    def coefficients(self):
        return (self.stiffness, self.threshold)


class DryFriction:
    """Coulomb friction on the rate of s(q): force -F_d sign(d s/dt) grad s(q), set-valued
    (anywhere in [-F_d, F_d]) when d s/dt = 0. Needs a velocity-level implicit solve."""

    kind = "dry_friction"

    def __init__(self, rate_of, bound, name=None):
        self.strain = sp.sympify(rate_of)
        self.bound = sp.sympify(bound)
        self.name = name

    def coefficients(self):
        return (self.bound, sp.S.Zero)


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
        _check_name("parameter", n)
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


def _check_name(kind, name):
    if not name.isidentifier() or keyword.iskeyword(name):
        raise ModelError(f"{kind} name {name!r} is not a valid Python identifier")


class Model:
    """A Lagrangian model. Build it in a model file and assign it to ``model``.

    Parameters
    ----------
    name : identifier used for the generated module (generated/<name>.py).
    coords : list of n Coordinate (or sympy.physics.mechanics dynamicsymbols).
    T : kinetic energy, quadratic in the velocities (scleronomic).
    V : potential energy V(q[, t]); default 0.
    forces : generalized forces Q(q, qdot, t): a length-n sequence, a dict {coordinate: Q}, or a
        list of PointForce (converted by virtual work). Non-conservative forces only; conservative
        ones belong in V.
    dissipation : Rayleigh function D(q, qdot); contributes Q = -dD/dqdot.
    constraints : list of holonomic constraints Phi(q) = 0.
    elements : nonsmooth elements (SaintVenant, DryFriction) acting on strains s(q).
    params : optional explicit parameter order; default: order of declaration.
    description : one line shown in the generated module's docstring.
    """

    def __init__(self, name, coords, T, V=0, forces=None, dissipation=0, constraints=(),
                 elements=(), params=None, description=""):
        _check_name("model", str(name))
        self.name = str(name)
        self.description = description
        coords = list(coords)
        if not coords:
            raise ModelError(f"model {name}: no coordinates")
        coords, replace = _convert_dynamicsymbols(coords)
        self.coords = coords
        self.T = self._scalar(T, "T", replace)
        self.V = self._scalar(V, "V", replace)
        self.dissipation = self._scalar(dissipation, "dissipation", replace)
        self.forces = self._generalized_forces(forces, replace)
        self.constraints = [self._scalar(c, f"constraint {i}", replace)
                            for i, c in enumerate(self._sequence(constraints, "constraints", "expressions Phi(q)"))]
        self.elements = self._elements(elements, replace)
        self.params = self._collect_params(params)
        self.source_path = None      # set by load_model
        self.source_text = ""
        self.build_options = {}
        self._validate()

    # -- construction helpers -------------------------------------------------------------
    @property
    def velocities(self):
        return [c.d for c in self.coords]

    @property
    def n_coords(self):
        return len(self.coords)

    @property
    def n_constraints(self):
        return len(self.constraints)

    def _scalar(self, expr, what, replace):
        try:
            return _sympify(expr, what, replace)
        except ModelError as exc:
            raise ModelError(f"model {self.name}: {exc}") from None

    def _sequence(self, items, what, of):
        """``items`` as a list; ModelError naming ``what`` when it is not a sequence."""
        if isinstance(items, (sp.Basic, str, bytes)) and not getattr(items, "is_Matrix", False):
            raise ModelError(f"model {self.name}: {what} must be a sequence of {of}, got {items}")
        try:
            return list(items)
        except TypeError:
            raise ModelError(f"model {self.name}: {what} must be a sequence of {of}, got {items!r}") from None

    def _generalized_forces(self, forces, replace):
        n = len(self.coords)
        Q = [sp.S.Zero] * n
        if forces is None:
            return Q
        if isinstance(forces, dict):
            for key, value in forces.items():
                key = replace.get(key, key)
                if key not in self.coords:
                    raise ModelError(f"model {self.name}: force given for {key}, which is not a coordinate")
                Q[self.coords.index(key)] += self._scalar(value, f"force on {key}", replace)
            return Q
        forces = self._sequence(forces, "forces", "one Q per coordinate (or a dict {coordinate: Q}, "
                                "or a list of PointForce)")
        if forces and all(isinstance(f, PointForce) for f in forces):
            for i, f in enumerate(forces):
                point = [self._scalar(r, f"point of PointForce {i}", replace) for r in f.point]
                force = [self._scalar(F, f"force of PointForce {i}", replace) for F in f.force]
                for rk, Fk in zip(point, force):
                    for j, qj in enumerate(self.coords):
                        Q[j] += Fk * sp.diff(rk, qj)
            return Q
        if len(forces) != n:
            raise ModelError(f"model {self.name}: forces has {len(forces)} entries for {n} coordinates "
                             "(give one per coordinate, a dict, or a list of PointForce)")
        return [self._scalar(f, f"force {i}", replace) for i, f in enumerate(forces)]

    def _elements(self, elements, replace):
        out = []
        for i, e in enumerate(elements):
            if not isinstance(e, (SaintVenant, DryFriction)):
                raise ModelError(f"model {self.name}: element {i} is {type(e).__name__}, not SaintVenant or DryFriction")
            e.name = e.name or f"{e.kind}_{i}"
            _check_name("element", e.name)
            e.strain = self._scalar(e.strain, f"strain of element {e.name}", replace)
            for c in e.coefficients():
                self._scalar(c, f"coefficient of element {e.name}", {})
            out.append(e)
        return out

    @property
    def n_elements(self):
        return len(self.elements)

    def _all_expressions(self):
        yield "T", self.T
        yield "V", self.V
        yield "dissipation", self.dissipation
        for c, f in zip(self.coords, self.forces):
            yield f"force on {c}", f
        for i, c in enumerate(self.constraints):
            yield f"constraint {i}", c
        for e in self.elements:
            yield f"strain of element {e.name}", e.strain
            for c in e.coefficients():
                yield f"coefficient of element {e.name}", c

    def _collect_params(self, explicit):
        """The parameters in PARAMS order: ``explicit`` (params=), or the used ones in
        declaration order. Fills param_defaults {name: default or None}."""
        found = {}
        for where, expr in self._all_expressions():
            for s in expr.free_symbols:
                if isinstance(s, Parameter) and found.setdefault(s.name, s) != s:
                    raise ModelError(f"model {self.name}: parameter {s.name} is declared twice (two "
                                     f"parameters() calls) and both are used ({where} uses one of "
                                     "them); declare it once and use that symbol")
        params = sorted(found.values(), key=lambda s: (s.declaration == 0, s.declaration, s.name))
        if explicit is not None:
            params = list(explicit)
            for s in params:
                if not isinstance(s, Parameter):
                    raise ModelError(f"model {self.name}: params entry {s} is not a Parameter")
            missing = [name for name, s in found.items() if s not in params]
            if missing:
                raise ModelError(f"model {self.name}: parameter(s) {', '.join(sorted(missing))} "
                                 "used but not in params=")
        self.param_defaults = {s.name: s.default for s in params}
        return params

    def _validate(self):
        names = {}
        for kind, syms in (("coordinate", self.coords), ("velocity", self.velocities),
                           ("parameter", self.params)):
            for s in syms:
                _check_name(kind, s.name)
                if s.name in names or s.name == "t":
                    other = names.get(s.name, "time")
                    raise ModelError(f"model {self.name}: duplicate name {s.name!r} ({other} and {kind})")
                names[s.name] = kind
        q, qd = set(self.coords), set(self.velocities)
        allowed = q | qd | set(self.params) | {t}
        for where, expr in self._all_expressions():
            unknown = sorted(str(s) for s in expr.free_symbols - allowed)
            if unknown:
                raise ModelError(f"model {self.name}: {where} uses symbol(s) {', '.join(unknown)} "
                                 "that are neither coordinates, velocities, parameters nor t")
            if expr.has(sp.Derivative) or expr.atoms(sp.core.function.AppliedUndef):
                raise ModelError(f"model {self.name}: {where} contains an undefined function or derivative: {expr}")
        if self.T.free_symbols & {t}:
            raise ModelError(f"model {self.name}: T depends on t; only scleronomic T is supported")
        moving = [f"{v} ({c}.d)" for c, v in zip(self.coords, self.velocities) if v in self.V.free_symbols]
        if moving:
            raise ModelError(f"model {self.name}: V depends on the velocit{'y' if len(moving) == 1 else 'ies'} "
                             f"{', '.join(moving)}; V is a function of q and t: velocity-dependent "
                             "potentials belong in T or in forces")
        _check_rayleigh(self.name, self.dissipation, self.velocities)
        if self.dissipation.free_symbols & {t}:
            raise ModelError(f"model {self.name}: dissipation depends on t")
        for i, c in enumerate(self.constraints):
            bad = sorted(str(s) for s in c.free_symbols & (qd | {t}))
            if bad:
                raise ModelError(f"model {self.name}: constraint {i} ({c}) depends on {', '.join(bad)}; "
                                 "only holonomic scleronomic constraints Phi(q) = 0 are supported")
        self._validate_elements(qd)
        if not (self.T.free_symbols & qd):
            raise ModelError(f"model {self.name}: T does not depend on any velocity")

    def _validate_elements(self, qd):
        for e in self.elements:
            bad = sorted(str(s) for s in e.strain.free_symbols & (qd | {t}))
            if bad:
                raise ModelError(f"model {self.name}: element {e.name}: the strain {e.strain} depends on "
                                 f"{', '.join(bad)}; a strain must be a function s(q) of the coordinates")
            for label, c in zip(("stiffness/bound", "threshold"), e.coefficients()):
                if c.free_symbols - set(self.params):
                    raise ModelError(f"model {self.name}: element {e.name}: {label} {c} must depend on parameters only")
                value = c.xreplace({p: sp.Float(p.default) for p in c.free_symbols
                                    if isinstance(p, Parameter) and p.default is not None})
                if e.kind == "dry_friction" and label == "threshold":
                    continue
                if value.is_number and not float(value) > 0:
                    raise ModelError(f"model {self.name}: element {e.name}: {label} must be > 0, got {c} = {float(value):g}")

    def defaults(self):
        """Default parameter values in PARAMS order (None where a value is required)."""
        return [self.param_defaults[p.name] for p in self.params]

    def __repr__(self):
        return (f"Model({self.name!r}, coords={[c.name for c in self.coords]}, "
                f"params={[p.name for p in self.params]}, constraints={len(self.constraints)})")


def _convert_dynamicsymbols(coords):
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
        if isinstance(c, sp.core.function.AppliedUndef) and len(c.args) == 1 and isinstance(c.args[0], sp.Symbol):
            time_sym = c.args[0]
            coord = Coordinate(str(c.func))
            replace[sp.Derivative(c, time_sym)] = coord.d
            replace[c] = coord
            replace[time_sym] = t
            out.append(coord)
            continue
        raise ModelError(f"coordinate {c!r} is neither a Coordinate nor a dynamicsymbol q(t)")
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


def _sympify(expr, what, replace):
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


def _check_rayleigh(name, D, velocities):
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


def _vanishes_at_rest(expr, s):
    value = expr.subs(s, 0)
    if value.has(sp.nan, sp.zoo, sp.oo, -sp.oo):
        value = sp.limit(expr, s, 0, "+")
    return value == 0 or sp.simplify(value) == 0
