"""The Dynamics record and the `derive` stage that fills it."""

from __future__ import annotations

from dataclasses import dataclass, field

import sympy as sp

from ..model import Model, t as time_symbol
from .constraints import derive_constraints
from .elements import derive_elements
from .jacobians import derive_jacobians
from .lagrangian import derive_lagrangian


@dataclass
class Dynamics:
    """Everything the generator prints, as sympy objects.

    Shapes (n coordinates, m constraints): H (n, n); h, g, Q, rhs, dTdq, momentum_rate (n, 1);
    Phi (m, 1); J (m, n); gamma (m, 1); E scalar. Jacobian matrices are (n, n) unless noted.
    The equations of motion are H qddot + h + g = Q + J^T lambda with Phi(q) = 0, and
    rhs = Q - h - g (smooth forces only: nonsmooth element forces are the steppers' business).
    Elements (ne of them): elem_s (ne, 1), elem_grad (ne, n), elem_coef (ne, 3),
    elem_hess_w (n, n). ``momentum_rate`` = dT/dq - dV/dq + Q is dp/dt for p = H qdot.
    """

    model: Model
    q: list
    qd: list
    params: list
    t: sp.Symbol
    H: sp.Matrix
    h: sp.Matrix
    g: sp.Matrix
    Q: sp.Matrix
    rhs: sp.Matrix
    dTdq: sp.Matrix
    momentum_rate: sp.Matrix
    E: sp.Expr
    Phi: sp.Matrix
    J: sp.Matrix
    gamma: sp.Matrix
    elem_s: sp.Matrix = None
    elem_grad: sp.Matrix = None
    elem_coef: sp.Matrix = None
    elem_hess_w: sp.Matrix = None
    jac: dict = field(default_factory=dict)
    aux: dict = field(default_factory=dict)   # auxiliary input vectors (w, lam) by name

    @property
    def n(self):
        return len(self.q)

    @property
    def m(self):
        return self.Phi.shape[0]

    @property
    def n_elements(self):
        return self.elem_s.shape[0]

    @property
    def mass_is_constant(self):
        return not (self.H.free_symbols & set(self.q))

    @property
    def forces_velocity_free(self):
        return not (self.rhs.free_symbols & set(self.qd))


def derive(model: Model, check_samples: int = 8) -> Dynamics:
    """Derive H, h, g, Q, constraints, energy and Newton Jacobians of a model.

    ``check_samples`` random states are used to check that T is quadratic in the velocities and
    H positive definite (ModelError naming the state otherwise).
    """
    parts = derive_lagrangian(model, check_samples=check_samples)
    cons = derive_constraints(model)
    dyn = Dynamics(model=model, q=list(model.coords), qd=list(model.velocities),
                   params=list(model.params), t=time_symbol, **parts, **cons)
    dyn.jac, dyn.aux = derive_jacobians(dyn)
    dyn.aux["we"] = list(sp.symbols(f"we_0:{len(model.elements)}", real=True))
    for key, value in derive_elements(model, dyn.aux["we"]).items():
        setattr(dyn, key, value)
    return dyn
