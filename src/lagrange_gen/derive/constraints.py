"""Holonomic constraints: Phi(q), J = dPhi/dq, gamma = -(dJ/dt) qdot."""

from __future__ import annotations

import sympy as sp

from .backend import jacobian


def derive_constraints(model):
    """Return dict(Phi (m, 1), J (m, n), gamma (m, 1)).

    gamma = -(sum_i dJ/dq_i qdot_i) qdot, so that the acceleration-level constraint reads
    J qddot = gamma.
    """
    q, qd = list(model.coords), list(model.velocities)
    n = len(q)
    Phi = sp.Matrix(model.constraints) if model.constraints else sp.zeros(0, 1)
    J = jacobian(Phi, q) if model.constraints else sp.zeros(0, n)
    qd_vec = sp.Matrix(qd)
    Jv = J * qd_vec
    gamma = -jacobian(Jv, q) * qd_vec if model.constraints else sp.zeros(0, 1)
    return dict(Phi=Phi, J=J, gamma=gamma)
