"""Unilateral contacts: gaps g(q), their Jacobians W_N = dg/dq, the tangent Jacobians
W_T = d(slip)/d(qdot) and the coefficients (restitution, friction), as sympy matrices."""

from __future__ import annotations

import sympy as sp

from .backend import backend_for, jacobian


def derive_contacts(model):
    """Return dict(contact_gap (c, 1), contact_WN (c, n), contact_WT (c, n), contact_coef (c, 2),
    contact_rate (2c, 1)).

    W_T's row is zero for a contact without a slip velocity (frictionless); contact_coef rows
    are (restitution e, friction mu). Gaps and slips are scleronomic (model/contacts.py refuses
    t), so there are no time-derivative terms: contact_rate = (dW_N/dt qdot, dW_T/dt qdot), the
    terms that make W qddot + contact_rate the local accelerations (d(W_N qdot)/dq qdot).
    """
    q, qd = list(model.coords), list(model.velocities)
    n, contacts = len(q), list(getattr(model, "contacts", ()))
    c = len(contacts)
    if not c:
        return dict(contact_gap=sp.zeros(0, 1), contact_WN=sp.zeros(0, n),
                    contact_WT=sp.zeros(0, n), contact_coef=sp.zeros(0, 2),
                    contact_rate=sp.zeros(0, 1))
    gap = sp.Matrix([k.gap for k in contacts])
    slip = sp.Matrix([k.slip if k.slip is not None else sp.S.Zero for k in contacts])
    WN = jacobian(gap, q, backend_for(list(gap)))
    WT = jacobian(slip, qd, backend_for(list(slip)))
    coef = sp.Matrix([list(k.coefficients()) for k in contacts])
    velocity = sp.Matrix(qd)
    local = sp.Matrix.vstack(WN * velocity, WT * velocity)
    rate = jacobian(local, q, backend_for(list(local))) * velocity
    return dict(contact_gap=gap, contact_WN=WN, contact_WT=WT, contact_coef=coef,
                contact_rate=rate)
