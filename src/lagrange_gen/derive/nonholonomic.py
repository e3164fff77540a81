"""Nonholonomic constraints c(q, qdot, t) = A(q, t) qdot + b(q, t) = 0 (Lagrange-d'Alembert):
A, b and the acceleration-level right-hand side, as sympy matrices; the derivatives of both kinds
of constraint rows that linearization about a motion needs."""

from __future__ import annotations

import sympy as sp

from .lagrangian import dot
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


def nonholonomic_jacobians(o, native, q, qd, w, mu):
    """The exact derivatives lagrange_gen.linearize needs about a motion, as native matrices:
    dict(dAw (r, n) = d(A w)/dq for an input vector w (n,), dATmu (n, n) = d(A^T mu)/dq for
    multipliers mu (r,), dc (r, n) = d(A qd + b)/dq (the velocity constraint's change with the
    configuration), dgamma_dq, dgamma_dqd (r, n)). ``native``: the Dynamics' native fields;
    q, qd, w, mu: native symbols."""
    A, b, gamma = native["nh_A"], native["nh_b"], native["nh_gamma"]
    r, n = A.shape
    zero = o.native(0)
    Aw = [dot([A[i, j] for j in range(n)], w, zero) for i in range(r)]
    ATmu = [dot([A[i, j] for i in range(r)], mu, zero) for j in range(n)]
    c = [dot([A[i, j] for j in range(n)], qd, zero) + b[i, 0] for i in range(r)]
    gam = [gamma[i, 0] for i in range(r)]
    return dict(dAw=o.jacobian(Aw, q), dATmu=o.jacobian(ATmu, q), dc=o.jacobian(c, q),
                dgamma_dq=o.jacobian(gam, q), dgamma_dqd=o.jacobian(gam, qd))


def constraint_gamma_jacobians(o, native, q, qd):
    """d gamma/dq and d gamma/dqd (m, n) of the holonomic constraints' acceleration right-hand
    side J qdd = gamma (third derivatives of Phi: linearize about a motion, not only about
    rest), as native matrices."""
    gam = [native["gamma"][i, 0] for i in range(native["gamma"].shape[0])]
    return dict(dgamma_dq=o.jacobian(gam, q), dgamma_dqd=o.jacobian(gam, qd))
