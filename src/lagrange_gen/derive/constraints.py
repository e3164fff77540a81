"""Holonomic constraints: Phi(q), J = dPhi/dq, gamma = -(dJ/dt) qdot, in native objects."""

from __future__ import annotations

from .lagrangian import _quadratic


def derive_constraints(model, o, q):
    """Return dict(Phi (m, 1), J (m, n), gamma (m, 1), d2Phi: m symmetric (n, n) Hessians).

    gamma_i = -qdot^T (d2 Phi_i/dq2) qdot, so that the acceleration-level constraint reads
    J qddot = gamma. The Hessians are computed once (upper triangle) and reused by the Newton
    Jacobians d(J w)/dq and d(J^T lam)/dq.
    """
    n = len(q)
    Phi = [o.native(c) for c in model.constraints]
    J = o.jacobian(Phi, q)
    d2Phi = []
    for i in range(len(Phi)):
        upper = {(k, l): J[i, k].diff(q[l]) for k in range(n) for l in range(k, n)}
        d2Phi.append(o.matrix(n, n, [upper[min(k, l), max(k, l)] for k in range(n) for l in range(n)]))
    qd = o.symbols(model.velocities)
    zero = o.native(0)
    gamma = [-_quadratic(d2, qd, zero) for d2 in d2Phi]
    return dict(Phi=o.column(Phi), J=J, gamma=o.column(gamma), d2Phi=d2Phi)
