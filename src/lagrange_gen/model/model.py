"""The user-facing model: coordinates, parameters, energies, forces and constraints.

A model file under ``models/`` builds a :class:`Model` from SymPy expressions and assigns it to a
variable named ``model`` (optionally it also defines ``build(**options)`` returning a Model, for
families such as the n-link pendulum). :func:`lagrange_gen.model.model_file.load_model` executes such
a file; Model converts what it is given (model/validation.py checks it). The module is over 300
lines because Model's docstring is the reference of every argument a model file may pass.
"""

from __future__ import annotations

import sympy as sp

from .intermediates import expand_intermediates, intermediates_of
from .drawing import Drawing, check_drawing
from .validation import check_model
from ..errors import ModelError
from .expressions import (Event, convert_dynamicsymbols, equation_as_expr, is_mechanics_load,
                          mechanics_speeds, named_events, prescriptions, sympify_scalar)
from .loads import DryFriction, PointForce, SaintVenant
from .contacts import Contact, check_contacts, named_contacts
from .nonholonomic import check_nonholonomic
from .symbols import Coordinate, Parameter, Velocity, check_name, coordinates, inputs, parameters, t

__all__ = [
    "Coordinate", "Velocity", "Parameter", "PointForce", "SaintVenant", "DryFriction", "Contact", "Event",
    "Model",
    "Drawing",
    "coordinates", "parameters", "t", "inputs",
]


class _IntermediateLabel:
    """"intermediate <name> of <definition>" for a message: a deep tree's definitions are long,
    and printing each one for a label that no message shows costs more than the checks."""

    __slots__ = ("sym",)

    def __init__(self, sym):
        self.sym = sym

    def __str__(self):
        return f"intermediate {self.sym.name} of {self.sym.definition}"


class Model:
    """A Lagrangian model. Build it in a model file and assign it to ``model``.

    Parameters
    ----------
    name : identifier used for the generated module (generated/<name>.py).
    coords : list of n Coordinate (or sympy.physics.mechanics dynamicsymbols).
    T : kinetic energy T(q, qdot, t) of degree <= 2 in the velocities, T = T2 + T1 + T0
        (rheonomic systems and rotating frames; see derive/lagrangian.py).
    V : potential energy V(q[, t]); default 0.
    forces : generalized forces Q(q, qdot, t): a length-n sequence, a dict {coordinate: Q}, or a
        list of loads converted by virtual work: PointForce, and sympy.physics.mechanics
        Force(Point, Vector), Torque(ReferenceFrame, Vector) or such (Point/ReferenceFrame,
        Vector) tuples (lagrange_gen.model.mechanics; they need ``frame``). Conservative forces may
        go in V instead.
    dissipation : Rayleigh function D(q, qdot); contributes Q = -dD/dqdot.
    constraints : list of holonomic constraints Phi(q) = 0 or Phi(q, t) = 0 (rheonomic; an
        sp.Eq(lhs, rhs) means lhs - rhs).
    nonholonomic : list of velocity constraints A(q, t) . qdot + b(q, t) = 0, each an expression
        linear in the velocities (or an sp.Eq): rolling without slipping, knife edges
        (model/nonholonomic.py); stepped by the methods for nonholonomic models.
    elements : nonsmooth elements (SaintVenant, DryFriction) acting on strains s(q).
    contacts : unilateral contacts Contact(gap=g(q, t), restitution=e, friction=mu, slip=u_T
        or (u_T1, u_T2)): g >= 0 with impacts (Newton's law) and Coulomb friction on the slip
        velocity (2D) or the pair of them (3D cone) (model/contacts.py); stepped by moreau_jean
        and dop853_impacts.
    events : {name: g} with g(q, qdot, t) an expression, or Event(g, terminal=, direction=):
        simulate locates the zero crossings of each g and records them (steppers/core/events.py).
    prescribed : {Coordinate: expression of t and parameters}: coordinates whose motion is
        given (a driven pivot, a crank turning at w t); each is substituted, with its velocity
        (the expression's time derivative), in every expression before anything is derived.
        They are not in coords.
    params : optional explicit parameter order; default: order of declaration.
    description : one line shown in the generated module's docstring.
    frame : the inertial sympy.physics.mechanics ReferenceFrame of mechanics loads in forces=.
    inputs : list of input symbols (``inputs("u1 u2")``), usable wherever a parameter is; they
        are the last entries of PARAMS (zero-order hold over a step, lagrange_gen.run.control).
    outputs : {name: y(q, qdot, t)} evaluated by the generated ``outputs`` kernel and saved
        with the trajectory (Trajectory.saved["output_<name>"]).
    draw : optional Drawing(points={name: (x, y[, z])}, segments=[(a, b)]) in q, parameters and t:
        what an animation shows (model/drawing.py; never generated, the module does not change).
    """

    def __init__(self, name, coords, T, V=0, forces=None, dissipation=0, constraints=(),
                 elements=(), params=None, description="", events=None, prescribed=None, frame=None,
                 inputs=(), outputs=None, draw=None, contacts=(), nonholonomic=()):
        check_name("model", str(name))
        self.name = str(name)
        self.description = description
        coords = list(coords)
        if not coords:
            raise ModelError(f"model {name}: no coordinates")
        speeds = mechanics_speeds(coords)
        coords, replace = convert_dynamicsymbols(coords)
        self.coords = coords
        self.T = self._scalar(T, "T", replace)
        self.V = self._scalar(V, "V", replace)
        self.dissipation = self._scalar(dissipation, "dissipation", replace)
        self.forces = self._generalized_forces(forces, replace, frame, speeds)
        self.constraints = [self._scalar(equation_as_expr(c), f"constraint {i}", replace)
                            for i, c in enumerate(self._sequence(constraints, "constraints", "expressions Phi(q)"))]
        self.nonholonomic = [
            self._scalar(equation_as_expr(c), f"nonholonomic constraint {i}", replace)
            for i, c in enumerate(self._sequence(nonholonomic, "nonholonomic",
                                                 "expressions A(q, t) . qdot + b(q, t)"))]
        self.elements = self._elements(elements, replace)
        self.contacts = self._contacts(contacts, replace)
        self.events = named_events(self.name, events, replace)
        self.inputs = self._inputs(inputs)
        self.outputs = {str(k): self._scalar(v, f"output {k}", replace) for k, v in (outputs or {}).items()}
        self.prescribed = prescriptions(self.name, prescribed, coords, replace)
        if self.prescribed:
            self._substitute_prescribed()
        self.intermediates = intermediates_of(*(e for _, e in self._expressions_and_events()))
        self.params = self._collect_params(params)
        self.source_path = None      # set by load_model
        self.source_text = ""
        self.build_options = {}
        check_model(self)
        check_contacts(self)
        check_nonholonomic(self)
        # A drawing may show a prescribed coordinate (the driven pivot): substituted like the rest.
        sub = getattr(self, "_prescribed_sub", {})
        self.draw = check_drawing(self, draw, lambda e, what: self._scalar(e, what, replace).xreplace(sub))

    # -- construction helpers -------------------------------------------------------------
    def _substitute_prescribed(self):
        """Replace each prescribed coordinate by its expression and its velocity by the time
        derivative of that expression, in every expression of the model."""
        sub = {}
        for c, expr in self.prescribed.items():
            sub[c], sub[c.d] = expr, sp.diff(expr, t)
        if intermediates_of(*(e for _, e in self._expressions_and_events())):
            # a prescribed coordinate inside an Intermediate's definition: substituted in the
            # expanded expressions (small models; the structured path has no prescriptions)
            self._expand_intermediates()
        self.T, self.V = self.T.xreplace(sub), self.V.xreplace(sub)
        self.dissipation = self.dissipation.xreplace(sub)
        self.forces = [f.xreplace(sub) for f in self.forces]
        self.constraints = [c.xreplace(sub) for c in self.constraints]
        self.nonholonomic = [c.xreplace(sub) for c in self.nonholonomic]
        for e in self.elements:
            e.strain = e.strain.xreplace(sub)
        for e in self.events:
            e.expr = e.expr.xreplace(sub)
        for c in self.contacts:
            c.gap = c.gap.xreplace(sub)
            c.slips = tuple(u.xreplace(sub) for u in c.slips)
        self.outputs = {k: y.xreplace(sub) for k, y in self.outputs.items()}
        self._prescribed_sub = sub

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
            return sympify_scalar(expr, what, replace)
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

    def _generalized_forces(self, forces, replace, frame=None, speeds=()):
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
        if forces and all(isinstance(f, PointForce) or is_mechanics_load(f) for f in forces):
            if any(is_mechanics_load(f) for f in forces):
                from .mechanics import generalized_loads
                mech = [f for f in forces if is_mechanics_load(f)]
                mech = self._fold_constant_forces(mech, frame, replace)
                for j, Qj in enumerate(generalized_loads(mech, frame, speeds, self.name)):
                    Q[j] += self._scalar(Qj, f"generalized force of the loads on {self.coords[j]}", replace)
                forces = [f for f in forces if not is_mechanics_load(f)]
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

    def _fold_constant_forces(self, loads, frame, replace):
        """The mechanics loads that stay generalized forces: constant forces at points (gravity
        as me.Force(G, -m*g*N.z)) become the potential -F . r_P, added to V, so a model with
        gravity written as a load stays conservative (energy conserved by the symplectic
        methods, no work to track)."""
        from .bodies import constant_force_potential, is_constant_force
        from .mechanics import where_and_vector
        if frame is None:
            return loads
        # sympy's Force objects only (how a model states gravity on a point); tuples and
        # PointForce stay generalized forces by virtual work, as written
        constant = [f for f in loads if type(f).__name__ == "Force" and is_constant_force(frame, where_and_vector(f))]
        potential = constant_force_potential(frame, [where_and_vector(f) for f in constant]) if constant else None
        if potential is None:
            return loads
        self.V = self.V + self._scalar(potential, "potential of the constant forces", replace)
        return [f for f in loads if not any(f is c for c in constant)]

    def _elements(self, elements, replace):
        out = []
        for i, e in enumerate(elements):
            if not isinstance(e, (SaintVenant, DryFriction)):
                raise ModelError(f"model {self.name}: element {i} is {type(e).__name__}, not SaintVenant or DryFriction")
            e.name = e.name or f"{e.kind}_{i}"
            check_name("element", e.name)
            e.strain = self._scalar(e.strain, f"strain of element {e.name}", replace)
            for c in e.coefficients():
                self._scalar(c, f"coefficient of element {e.name}", {})
            out.append(e)
        return out

    @property
    def n_elements(self):
        return len(self.elements)

    def _contacts(self, contacts, replace):
        out = named_contacts(self.name, self._sequence(contacts, "contacts", "Contact"))
        for c in out:
            c.gap = self._scalar(c.gap, f"gap of contact {c.name}", replace)
            c.slips = tuple(self._scalar(u, f"slip of contact {c.name}", replace)
                            for u in c.slips)
            c.restitution = self._scalar(c.restitution, f"restitution of contact {c.name}", {})
            c.friction = self._scalar(c.friction, f"friction of contact {c.name}", {})
        return out

    @property
    def n_contacts(self):
        return len(self.contacts)

    @property
    def n_nonholonomic(self):
        return len(self.nonholonomic)

    def _all_expressions(self):
        yield "T", self.T
        yield "V", self.V
        yield "dissipation", self.dissipation
        for c, f in zip(self.coords, self.forces):
            yield f"force on {c}", f
        for i, c in enumerate(self.constraints):
            yield f"constraint {i}", c
        for i, c in enumerate(self.nonholonomic):
            yield f"nonholonomic constraint {i}", c
        for e in self.elements:
            yield f"strain of element {e.name}", e.strain
            for c in e.coefficients():
                yield f"coefficient of element {e.name}", c
        for c in self.contacts:
            yield f"gap of contact {c.name}", c.gap
            for u in c.slips:
                yield f"slip of contact {c.name}", u
            for k in c.coefficients():
                yield f"coefficient of contact {c.name}", k

    def _expressions_and_events(self):
        """_all_expressions, the events and the outputs, as the user gave them."""
        yield from self._all_expressions()
        for e in self.events:
            yield f"event {e.name}", e.expr
        for name, y in self.outputs.items():
            yield f"output {name}", y

    def input_expressions(self):
        """Everything whose symbols must be known: _all_expressions, the events, the outputs
        and the definitions of the Intermediates they use (bodies.py). The events stay out of
        _all_expressions, which chooses the derivation backend (derive/backend.py): an event is
        evaluated, never differentiated."""
        yield from self._expressions_and_events()
        for sym in self.intermediates:
            yield _IntermediateLabel(sym), sym.definition

    def symbols_of(self, expr):
        """The free symbols of ``expr`` seen through its Intermediates' definitions."""
        out = set()
        for s in expr.free_symbols:
            out |= self._intermediate_symbols.get(s, {s})
        return out

    @property
    def _intermediate_symbols(self):
        table = self.__dict__.get("_symbols_table")
        if table is None or len(table) != len(self.intermediates):
            table = {}
            for sym in self.intermediates:       # definitions come after what they use
                table[sym] = set().union(*(table.get(u, {u}) for u in sym.definition.free_symbols))
            self.__dict__["_symbols_table"] = table
        return table

    def _expand_intermediates(self):
        """Replace every Intermediate by its definition in every expression (exact; large on
        deep trees)."""
        self.T, self.V = expand_intermediates(self.T), expand_intermediates(self.V)
        self.dissipation = expand_intermediates(self.dissipation)
        self.forces = [expand_intermediates(f) for f in self.forces]
        self.constraints = [expand_intermediates(c) for c in self.constraints]
        self.nonholonomic = [expand_intermediates(c) for c in self.nonholonomic]
        for e in self.elements:
            e.strain = expand_intermediates(e.strain)
        for e in self.events:
            e.expr = expand_intermediates(e.expr)
        for c in self.contacts:
            c.gap = expand_intermediates(c.gap)
            c.slips = tuple(expand_intermediates(u) for u in c.slips)
        self.outputs = {k: expand_intermediates(y) for k, y in self.outputs.items()}

    def _inputs(self, given):
        """The input symbols (Parameters declared by inputs()), checked."""
        out = self._sequence(given, "inputs", "symbols declared by inputs()")
        for u in out:
            if not isinstance(u, Parameter):
                raise ModelError(f"model {self.name}: input {u} is not declared by "
                                 f"lagrange_gen.inputs(); write {u} = inputs({str(u)!r})")
        if len(set(out)) != len(out):
            raise ModelError(f"model {self.name}: an input is listed twice in inputs=")
        return out

    def _collect_params(self, explicit):
        """The parameters in PARAMS order: ``explicit`` (params=), or the used ones in
        declaration order. Fills param_defaults {name: default or None}."""
        found = {}
        for where, expr in self.input_expressions():
            for s in expr.free_symbols:
                if isinstance(s, Parameter) and found.setdefault(s.name, s) != s:
                    raise ModelError(f"model {self.name}: parameter {s.name} is declared twice (two "
                                     f"parameters() calls) and both are used ({where} uses one of "
                                     "them); declare it once and use that symbol")
        # Inputs are the trailing parameters, in inputs= order (their slots are the loop's).
        params = sorted((s for s in found.values() if s not in self.inputs),
                        key=lambda s: (s.declaration == 0, s.declaration, s.name))
        if explicit is not None:
            params = [s for s in explicit if s not in self.inputs]
            for s in params:
                if not isinstance(s, Parameter):
                    raise ModelError(f"model {self.name}: params entry {s} is not a Parameter "
                                     "(declare it with lagrange_gen.parameters)")
            missing = [name for name, s in found.items() if s not in params and s not in self.inputs]
            if missing:
                raise ModelError(f"model {self.name}: parameter(s) {', '.join(sorted(missing))} "
                                 "used but not in params=")
        params = params + list(self.inputs)
        self.param_defaults = {s.name: s.default for s in params}
        return params

    def defaults(self):
        """Default parameter values in PARAMS order (None where a value is required)."""
        return [self.param_defaults[p.name] for p in self.params]

    def __repr__(self):
        return (f"Model({self.name!r}, coords={[c.name for c in self.coords]}, "
                f"params={[p.name for p in self.params]}, constraints={len(self.constraints)})")
