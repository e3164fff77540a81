"""Derivatives that Newton-based steppers need, all exact (no finite differences)."""

from __future__ import annotations

import sympy as sp

from .backend import jacobian


def derive_jacobians(dyn):
    """Return (jacobians, auxiliary symbols).

    jacobians (by name, shapes for n coordinates, m constraints):
      drhs_dq, drhs_dqd (n, n)   of rhs = Q - h - g
      dmom_dq, dmom_dqd (n, n)   of momentum_rate = dT/dq - dV/dq + Q
      dHw_dq (n, n)              d(H(q) w)/dq for an input vector w
      dJw_dq (m, n)              d(J(q) w)/dq
      dJTlam_dq (n, n)           d(J(q)^T lam)/dq, symmetric
    auxiliary symbols: {"w": [n symbols], "lam": [m symbols]} that become kernel inputs.
    """
    q, qd = dyn.q, dyn.qd
    n, m = len(q), dyn.Phi.shape[0]
    w = sp.Matrix(sp.symbols(f"w_0:{n}", real=True)) if n else sp.zeros(0, 1)
    lam = sp.Matrix(sp.symbols(f"lam_0:{m}", real=True)) if m else sp.zeros(0, 1)
    jac = {
        "drhs_dq": jacobian(dyn.rhs, q),
        "drhs_dqd": jacobian(dyn.rhs, qd),
        "dmom_dq": jacobian(dyn.momentum_rate, q),
        "dmom_dqd": jacobian(dyn.momentum_rate, qd),
        "dHw_dq": jacobian(dyn.H * w, q),
    }
    if m:
        jac["dJw_dq"] = jacobian(dyn.J * w, q)
        jac["dJTlam_dq"] = jacobian(dyn.J.T * lam, q)
    else:
        jac["dJw_dq"] = sp.zeros(0, n)
        jac["dJTlam_dq"] = sp.zeros(n, n)
    return jac, {"w": list(w), "lam": list(lam)}
