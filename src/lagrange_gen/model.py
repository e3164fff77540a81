"""The user-facing model: coordinates, parameters, energies, forces and constraints.

A model file under ``models/`` builds a :class:`Model` from SymPy expressions and assigns it to a
variable named ``model`` (optionally it also defines ``build(**options)`` returning a Model, for
families such as the n-link pendulum). :func:`lagrange_gen.model_file.load_model` executes such
a file; Model validates what it is given.
"""

from __future__ import annotations

import sympy as sp

from .errors import ModelError
from .loads import DryFriction, PointForce, SaintVenant
from .model_input import Event, _check_rayleigh, _convert_dynamicsymbols, _events, _sympify
from .symbols import Coordinate, Parameter, Velocity, _check_name, coordinates, parameters, t

__all__ = [
    "Coordinate", "Velocity", "Parameter", "PointForce", "SaintVenant", "DryFriction", "Event", "Model",
    "coordinates", "parameters", "t",
]


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
    events : {name: g} with g(q, qdot, t) an expression, or Event(g, terminal=, direction=):
        simulate locates the zero crossings of each g and records them (steppers/events.py).
    params : optional explicit parameter order; default: order of declaration.
    description : one line shown in the generated module's docstring.
    """

    def __init__(self, name, coords, T, V=0, forces=None, dissipation=0, constraints=(),
                 elements=(), params=None, description="", events=None):
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
        self.events = _events(self.name, events, replace)
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

    def _input_expressions(self):
        """_all_expressions and the events: everything whose symbols must be known. The events
        stay out of _all_expressions, which chooses the derivation backend (derive/backend.py):
        an event is evaluated, never differentiated."""
        yield from self._all_expressions()
        for e in self.events:
            yield f"event {e.name}", e.expr

    def _collect_params(self, explicit):
        """The parameters in PARAMS order: ``explicit`` (params=), or the used ones in
        declaration order. Fills param_defaults {name: default or None}."""
        found = {}
        for where, expr in self._input_expressions():
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
        for where, expr in self._input_expressions():
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
