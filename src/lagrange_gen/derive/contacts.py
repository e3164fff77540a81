"""Unilateral contacts: gaps g(q, t), their Jacobians W_N = dg/dq, the tangent Jacobians
W_T = d(slip)/d(qdot), the velocity terms of a moving surface and the coefficients (restitution,
friction), as sympy matrices."""

from __future__ import annotations

import sympy as sp

from .backend import backend_for, jacobian
from ..model.symbols import t


def derive_contacts(model):
    """Return dict(contact_gap (c, 1), contact_WN (c, n), contact_WT (2c, n), contact_coef (c, 2),
    contact_bias (3c, 1), contact_rate (3c, 1)).

    The local rows are ordered (normal (c), tangent 1 (c), tangent 2 (c)): W_T's row a is the
    first slip velocity's d/dqdot of contact a, row c + a the second's (zero rows for a contact
    with fewer slip velocities: frictionless, or the 2D law). contact_coef rows are
    (restitution e, friction mu). The local velocities are u = W qdot + contact_bias, the bias
    (dg/dt, b_T1, b_T2) being what a moving surface adds (zero for scleronomic contacts: the slip
    velocities are W_T(q, t) qdot + b_T(q, t)). Along a motion du/dt = W qddot + contact_rate with
    contact_rate = (du/dq) qdot + du/dt at fixed qdot (dW/dq qdot qdot, dW/dt qdot, db/dq qdot
    and the second time derivative of the gap).
    """
    q, qd = list(model.coords), list(model.velocities)
    n, contacts = len(q), list(getattr(model, "contacts", ()))
    c = len(contacts)
    if not c:
        return dict(contact_gap=sp.zeros(0, 1), contact_WN=sp.zeros(0, n),
                    contact_WT=sp.zeros(0, n), contact_coef=sp.zeros(0, 2),
                    contact_bias=sp.zeros(0, 1), contact_rate=sp.zeros(0, 1))
    gap = sp.Matrix([k.gap for k in contacts])
    slip = sp.Matrix([_slip(k, 0) for k in contacts] + [_slip(k, 1) for k in contacts])
    WN = jacobian(gap, q, backend_for(list(gap)))
    WT = jacobian(slip, qd, backend_for(list(slip)))
    coef = sp.Matrix([list(k.coefficients()) for k in contacts])
    velocity = sp.Matrix(qd)
    bias = sp.Matrix.vstack(gap.diff(t), slip.xreplace({v: 0 for v in qd}))
    local = sp.Matrix.vstack(WN * velocity, WT * velocity) + bias
    rate = jacobian(local, q, backend_for(list(local))) * velocity + local.diff(t)
    return dict(contact_gap=gap, contact_WN=WN, contact_WT=WT, contact_coef=coef,
                contact_bias=bias, contact_rate=rate)


def _slip(contact, k):
    """Slip velocity k (0 or 1) of a contact; 0 where it has none."""
    return contact.slips[k] if k < len(contact.slips) else sp.S.Zero
