"""The Dynamics record and the `derive` stage that fills it."""

from __future__ import annotations

import sympy as sp

from .backend import backend_for, ops
from .constraints import derive_constraints
from .contacts import derive_contacts
from .nonholonomic import derive_nonholonomic
from .elements import derive_elements
from .freeze import freeze_model
from .jacobians import Jacobians
from .lagrangian import derive_lagrangian
from .structured import (GraphJacobians, NotScleronomic, derive_lagrangian_graph, graph_model, import_expressions,
                         uses_graph)
from ..model.joint_form import joint_form
from ..model.model import Model, t as time_symbol
from .recursive import recursive_dynamics

#: Fields readable as sympy objects (converted from the backend's native objects on first read).
FIELDS = ("H", "h", "g", "Q", "rhs", "dTdq", "momentum_rate", "E", "Phi", "J", "gamma", "Phi_t", "b", "db", "power",
          "elem_s", "elem_grad", "elem_coef", "elem_hess_w",
          "contact_gap", "contact_WN", "contact_WT", "contact_coef", "contact_bias", "contact_rate", "nh_A", "nh_b", "nh_gamma")


class Dynamics:
    """Everything the generator prints.

    Shapes (n coordinates, m constraints): H (n, n); h, g, Q, rhs, dTdq, momentum_rate (n, 1);
    Phi, Phi_t = dPhi/dt (m, 1); J (m, n); gamma (m, 1); E scalar (the energy function
    T2 - T0 + V, T + V when T is scleronomic). Jacobian matrices are (n, n) unless noted.
    The equations of motion are H qddot + h + g = Q + J^T lambda with Phi(q) = 0, and
    rhs = Q - h - g (smooth forces only: nonsmooth element forces are the steppers' business).
    Elements (ne of them): elem_s (ne, 1), elem_grad (ne, n), elem_coef (ne, 3),
    elem_hess_w (n, n). Contacts (c of them): contact_gap (c, 1), contact_WN = d gap/dq (c, n),
    contact_WT = d slip/d qdot (2c, n) (tangent 1 rows, then tangent 2), contact_coef (c, 2) =
    (restitution, friction), contact_bias (3c, 1) (local velocities u = W qdot + bias: a moving
    surface's terms), contact_rate (3c, 1) (du/dt = W qddot + contact_rate); derive/contacts.py.
    Nonholonomic constraints (r of them, A qdot + b = 0, forces A^T mu): nh_A (r, n), nh_b
    (r, 1), nh_gamma (r, 1) with A qddot = gamma along a motion (derive/nonholonomic.py).
    ``momentum_rate`` = dL/dq + Q_nc is dp/dt for the canonical momentum
    p = H qdot + b, b (n, 1) = dT/dqdot at qdot = 0 (T1 = b . qdot), db = db/dq (n, n).

    Each field is a sympy Matrix (or Expr) built from ``native[field]`` when first read; code
    generation reads ``native`` and ``jac.native(name)`` and never pays for the conversion.
    ``model`` is the model as derived (frozen parameters substituted; ``frozen`` {name: value}).
    """

    def __init__(self, model, ops_, native, jac_parts, aux, frozen, jacobians=Jacobians):
        self.model, self.ops, self.native, self.aux, self.frozen = model, ops_, native, aux, frozen
        self.q, self.qd = list(model.coords), list(model.velocities)
        self.params, self.t = list(model.params), time_symbol
        self._names = {s.name: s for s in self.q + self.qd + self.params + [time_symbol]}
        self._names.update({s.name: s for v in aux.values() for s in v})
        o = ops_
        self.jac = jacobians(o, jac_parts, o.symbols(self.q), o.symbols(self.qd),
                             o.symbols(aux["w"]), o.symbols(aux["lam"]), self.to_sympy)
        self._sympy = {}
        #: derive.recursive.RecursiveDynamics when T is a tree of joints (else None)
        self.recursive = None

    def to_sympy(self, obj):
        return self.ops.to_sympy(obj, self._names)

    def __getattr__(self, name):
        if name in FIELDS:
            if name not in self._sympy:
                self._sympy[name] = self.to_sympy(self.native[name])
            return self._sympy[name]
        raise AttributeError(name)

    @property
    def n(self):
        return len(self.q)

    @property
    def m(self):
        return self.native["Phi"].shape[0]

    @property
    def n_elements(self):
        return self.native["elem_s"].shape[0]

    @property
    def n_contacts(self):
        return self.native["contact_gap"].shape[0]

    @property
    def n_nonholonomic(self):
        return self.native["nh_A"].shape[0]

    @property
    def mass_is_constant(self):
        return not ({str(s) for s in self.native["H"].free_symbols} & ({s.name for s in self.q} | {"t"}))

    @property
    def has_work(self):
        """True when E = T2 - T0 + V is not conserved: non-conservative forces, dissipation or
        an explicit t in L (P = qd . Q_nc - dL/dt nonzero), or nonsmooth elements (which
        dissipate; steppers/core/work.py)."""
        return self.native["power"][0, 0] != 0 or self.n_elements > 0

    @property
    def has_transport(self):
        """True when T has a term T1 = b(q, t) . qdot linear in the velocities."""
        return any(e != 0 for e in self.native["b"])

    @property
    def mass_depends_on_t(self):
        return "t" in {str(s) for s in self.native["H"].free_symbols}

    @property
    def constraints_rheonomic(self):
        """True when some constraint Phi(q, t) depends on t (Phi_t nonzero)."""
        return any(e != 0 for e in self.native["Phi_t"])

    @property
    def forces_velocity_free(self):
        return not ({str(s) for s in self.native["rhs"].free_symbols} & {s.name for s in self.qd})


def input_symbols(vector, count):
    """Symbols for the entries of a kernel input vector (w, lam, we), named ``w[0]``, ``w[1]``,
    ...: not identifiers, so no coordinate or parameter (identifiers, by Model's check) shares a
    name with them in the name-keyed maps of the backend (to_sympy) and of CSE. The printer gives
    them placeholders (codegen.printer.Inputs) like every other input."""
    return [sp.Symbol(f"{vector}[{i}]", real=True) for i in range(count)]


def derive(model: Model, check_samples: int = 8, freeze=None) -> Dynamics:
    """Derive H, h, g, Q, constraints, energy (and, on demand, Newton Jacobians) of a model.

    ``check_samples`` random states are used to check that T is quadratic in the velocities and
    H positive definite (ModelError naming the state otherwise). ``freeze`` {parameter name:
    value} substitutes those parameters by numbers before anything is derived.
    """
    frozen = dict(freeze or {})
    links = joint_form(model.T)          # the record is keyed by the T kinetic_energy returned
    model = freeze_model(model, frozen) if frozen else model
    if uses_graph(model):
        try:
            return _derive_through_graph(model, frozen, check_samples, links)
        except NotScleronomic:
            pass
    if getattr(model, "intermediates", ()):
        model = graph_model(model, expand_all=True)
    o = ops(backend_for(expr for _, expr in model._all_expressions()))
    parts = derive_lagrangian(model, o, check_samples=check_samples)
    return _finish(model, o, parts, frozen, Jacobians)


def _finish(model, o, parts, frozen, jacobians):
    """Constraints, elements and the Dynamics record around the Lagrangian ``parts``."""
    q = o.symbols(model.coords)
    parts.update(derive_constraints(model, o, q))
    n, m = len(model.coords), len(model.constraints)
    aux = {"w": input_symbols("w", n), "qdd": input_symbols("qdd", n), "lam": input_symbols("lam", m),
           "mu": input_symbols("mu", len(getattr(model, "nonholonomic", ()))),
           "we": input_symbols("we", len(model.elements))}
    for key, value in derive_elements(model, aux["we"]).items():
        parts[key] = o.matrix(*value.shape, list(value))
    for key, value in (*derive_contacts(model).items(), *derive_nonholonomic(model).items()):
        parts[key] = o.matrix(*value.shape, list(value))
    native = {k: parts[k] for k in FIELDS}
    return Dynamics(model, o, native, parts, aux, frozen, jacobians)


def _derive_through_graph(model, frozen, check_samples, links=None):
    """derive() for a model over Intermediates (derive/structured.py); with ``links`` (its T
    as a tree of joints, model/joint_form.py) also the recursive algorithms (derive/recursive.py)
    when they reproduce the graph's dynamics."""
    model = graph_model(model)
    o, (T, V, D, *forces) = import_expressions(model, frozen, [model.T, model.V, model.dissipation, *model.forces])
    parts = derive_lagrangian_graph(model, o, T, V, D, forces, check_samples)
    dyn = _finish(model, o, parts, frozen, GraphJacobians)
    if links is not None:
        dyn.recursive = recursive_dynamics(links, o, model, T, parts, o.symbols(dyn.aux["qdd"]), frozen)
    return dyn
