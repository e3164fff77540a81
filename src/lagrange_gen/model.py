"""The user-facing model: coordinates, parameters, energies, forces and constraints.

A model file under ``models/`` builds a :class:`Model` from SymPy expressions and assigns it to a
variable named ``model`` (optionally it also defines ``build(**options)`` returning a Model, for
families such as the n-link pendulum). :func:`load_model` executes such a file and validates it.
"""

from __future__ import annotations

import keyword
import runpy
import traceback
from dataclasses import dataclass
from pathlib import Path

import sympy as sp

from .errors import ModelError

__all__ = [
    "Coordinate", "Velocity", "Parameter", "PointForce", "SaintVenant", "DryFriction", "Model",
    "coordinates", "parameters", "t", "load_model",
]

#: The time symbol. Forces and potentials may depend on it; T and constraints may not.
t = sp.Symbol("t", real=True)

# Defaults of declared parameters, by name, in declaration order. Defaults are not stored on the
# symbols: sympy caches expressions, so an "equal" symbol from another model file can come back
# from the cache, and it must not bring another file's default or position with it. load_model
# starts each file with an empty table.
_declared: dict = {}


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
    """A model parameter; its default value is recorded by :func:`parameters`."""

    def __new__(cls, name):
        return super().__new__(cls, name, real=True)


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
    """Create parameters, e.g. ``parameters("m l g", defaults=(1.0, 1.0, 9.81))``.

    ``defaults`` may be a sequence (same length), a dict by name, or None (values required at
    simulation time). Returns a list of :class:`Parameter` (a single one when one name is given).
    """
    names = _split_names(names)
    if defaults is None:
        values = [None] * len(names)
    elif isinstance(defaults, dict):
        values = [defaults.get(n) for n in names]
    else:
        values = list(defaults)
        if len(values) != len(names):
            raise ModelError(f"parameters({' '.join(names)!r}): {len(names)} names but {len(values)} defaults")
    for n, v in zip(names, values):
        _check_name("parameter", n)
        _declared[n] = None if v is None else float(v)
    params = [Parameter(n) for n in names]
    return params[0] if len(params) == 1 else params


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
        self.T = _sympify(T, "T", replace)
        self.V = _sympify(V, "V", replace)
        self.dissipation = _sympify(dissipation, "dissipation", replace)
        self.forces = self._generalized_forces(forces, replace)
        self.constraints = [_sympify(c, f"constraint {i}", replace) for i, c in enumerate(constraints)]
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
                Q[self.coords.index(key)] += _sympify(value, f"force on {key}", replace)
            return Q
        forces = list(forces)
        if forces and all(isinstance(f, PointForce) for f in forces):
            for f in forces:
                for rk, Fk in zip(f.point, f.force):
                    rk, Fk = _apply(rk, replace), _apply(Fk, replace)
                    for j, qj in enumerate(self.coords):
                        Q[j] += Fk * sp.diff(rk, qj)
            return Q
        if len(forces) != n:
            raise ModelError(f"model {self.name}: forces has {len(forces)} entries for {n} coordinates "
                             "(give one per coordinate, a dict, or a list of PointForce)")
        return [_sympify(f, f"force {i}", replace) for i, f in enumerate(forces)]

    def _elements(self, elements, replace):
        out = []
        for i, e in enumerate(elements):
            if not isinstance(e, (SaintVenant, DryFriction)):
                raise ModelError(f"model {self.name}: element {i} is {type(e).__name__}, not SaintVenant or DryFriction")
            e.name = e.name or f"{e.kind}_{i}"
            _check_name("element", e.name)
            e.strain = _sympify(e.strain, f"strain of element {e.name}", replace)
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
        found = {}
        for _, expr in self._all_expressions():
            for s in expr.free_symbols:
                if isinstance(s, Parameter):
                    found.setdefault(s.name, s)
        self.param_defaults = {name: _declared.get(name) for name in found}
        if explicit is not None:
            explicit = list(explicit)
            for s in explicit:
                if not isinstance(s, Parameter):
                    raise ModelError(f"model {self.name}: params entry {s} is not a Parameter")
                self.param_defaults.setdefault(s.name, _declared.get(s.name))
            missing = sorted(set(found) - {s.name for s in explicit})
            if missing:
                raise ModelError(f"model {self.name}: parameter(s) {', '.join(missing)} used but not in params=")
            return explicit
        position = {name: i for i, name in enumerate(_declared)}
        return sorted(found.values(), key=lambda s: (position.get(s.name, len(position)), s.name))

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
                value = c.xreplace({p: sp.Float(_declared[p.name]) for p in c.free_symbols
                                    if _declared.get(p.name) is not None})
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
    try:
        expr = sp.sympify(expr)
    except (sp.SympifyError, TypeError) as exc:
        raise ModelError(f"{what} is not a SymPy expression: {exc}") from None
    if not isinstance(expr, sp.Expr):
        raise ModelError(f"{what} is not a scalar SymPy expression: {expr!r}")
    return _apply(expr, replace) if replace else expr


def load_model(path, **options) -> Model:
    """Execute a model file and return its validated Model.

    With ``options`` the file must define ``build(**options)`` (e.g. ``n=8`` for the n-link
    pendulum); otherwise it must assign a Model to ``model``. Every failure is a ModelError whose
    message names the file.
    """
    path = Path(path)
    if not path.is_file():
        raise ModelError(f"{path}: no such model file")
    if path.suffix != ".py":
        raise ModelError(f"{path}: a model file must be a Python file ending in .py")
    try:
        source = path.read_text()
    except (OSError, UnicodeDecodeError) as exc:
        raise ModelError(f"{path}: cannot read: {exc}") from None
    try:
        compile(source, str(path), "exec")
    except SyntaxError as exc:
        raise ModelError(f"{path}:{exc.lineno}: not valid Python: {exc.msg}") from None
    _declared.clear()
    try:
        namespace = runpy.run_path(str(path), run_name=f"lagrange_gen_model_{path.stem}")
        model = _pick_model(path, namespace, options)
    except ModelError as exc:
        msg = str(exc)
        raise ModelError(msg if msg.startswith(str(path)) else f"{path}: {msg}") from None
    except Exception as exc:  # the user's code raised: report file and line, not a traceback
        line = _user_line(exc, path)
        raise ModelError(f"{path}{line}: raised {type(exc).__name__}: {exc}") from exc
    model.source_path = str(path)
    model.source_text = source
    model.build_options = dict(options)
    return model


def _pick_model(path, namespace, options):
    if options:
        build = namespace.get("build")
        if not callable(build):
            raise ModelError(f"{path}: options {options} given but the file defines no build(**options)")
        model = build(**options)
    else:
        model = namespace.get("model")
        if model is None:
            found = [v for v in namespace.values() if isinstance(v, Model)]
            if len(found) == 1:
                model = found[0]
    if not isinstance(model, Model):
        raise ModelError(f"{path}: defines no Model (assign one to a variable named `model`)")
    return model


def _user_line(exc, path):
    for frame in reversed(traceback.extract_tb(exc.__traceback__)):
        if Path(frame.filename).resolve() == path.resolve():
            return f":{frame.lineno}"
    return ""
