"""Nonholonomic constraints c(q, qdot, t) = A(q, t) qdot + b(q, t) = 0 (Lagrange-d'Alembert):
A, b and the acceleration-level right-hand side, as sympy matrices."""

from __future__ import annotations

import sympy as sp

from ..model.symbols import t


def derive_nonholonomic(model):
    """Return dict(nh_A (r, n), nh_b (r, 1), nh_gamma (r, 1)) for the model's r nonholonomic
    constraints.

    The equations of motion are H qdd + h + g = Q + A^T mu with A qdot + b = 0 (the constraint
    forces A^T mu do no virtual work on the velocities A allows). Differentiating the constraint
    along a motion, A qdd + (dc/dq) qdot + dc/dt = 0 with c = A qdot + b and the partial
    derivatives at fixed qdot (they hold dA/dt qdot + db/dt), so A qdd = gamma with
    gamma = -((dc/dq) qdot + dc/dt). b is c at qdot = 0 (c is linear in qdot: checked by
    model/nonholonomic.py).
    """
    q, qd = list(model.coords), list(model.velocities)
    n, rows = len(q), list(getattr(model, "nonholonomic", ()))
    if not rows:
        return dict(nh_A=sp.zeros(0, n), nh_b=sp.zeros(0, 1), nh_gamma=sp.zeros(0, 1))
    c = sp.Matrix(rows)
    A = c.jacobian(qd)
    b = c.xreplace({v: 0 for v in qd})
    gamma = -(c.jacobian(q) * sp.Matrix(qd) + c.diff(t))
    return dict(nh_A=A, nh_b=b, nh_gamma=gamma)
