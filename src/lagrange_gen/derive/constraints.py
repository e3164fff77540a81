"""Holonomic constraints Phi(q, t) = 0: J = dPhi/dq, Phi_t = dPhi/dt and gamma, the
acceleration-level right-hand side, in native objects."""

from __future__ import annotations

from .lagrangian import dot, quadratic_form
from ..model.symbols import t


def derive_constraints(model, o, q):
    """Return dict(Phi, Phi_t (m, 1), J (m, n), gamma (m, 1), d2Phi: m symmetric (n, n) Hessians).

    Along a motion Phi(q(t), t) = 0 gives J qdot + Phi_t = 0 (the velocity constraint) and,
    differentiating again, J qddot + qdot^T Phi_qq qdot + 2 Phi_qt . qdot + Phi_tt = 0, so
    gamma_i = -(qdot^T (d2 Phi_i/dq2) qdot + 2 (d Phi_t,i/dq) . qdot + d2 Phi_i/dt2) and the
    acceleration-level constraint reads J qddot = gamma. The time terms vanish for scleronomic
    constraints and are then not emitted. The Hessians are computed once (upper triangle) and
    reused by the Newton Jacobians d(J w)/dq and d(J^T lam)/dq.
    """
    n = len(q)
    time = o.native(t)
    Phi = [o.native(c) for c in model.constraints]
    J = o.jacobian(Phi, q)
    d2Phi = []
    for i in range(len(Phi)):
        upper = {(k, l): J[i, k].diff(q[l]) for k in range(n) for l in range(k, n)}
        d2Phi.append(o.matrix(n, n, [upper[min(k, l), max(k, l)] for k in range(n) for l in range(n)]))
    qd = o.symbols(model.velocities)
    zero = o.native(0)
    Phi_t = [c.diff(time) for c in Phi]
    gamma = []
    for i, d2 in enumerate(d2Phi):
        g = -quadratic_form(d2, qd, zero)
        if Phi_t[i] != 0:
            g = g - 2 * dot([J[i, k].diff(time) for k in range(n)], qd, zero) - Phi_t[i].diff(time)
        gamma.append(g)
    return dict(Phi=o.column(Phi), J=J, gamma=o.column(gamma), d2Phi=d2Phi, Phi_t=o.column(Phi_t))
