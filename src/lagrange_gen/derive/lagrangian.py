"""H, h (Christoffel form), g, Q, energy: the unconstrained Lagrangian part."""

from __future__ import annotations

import numpy as np
import sympy as sp

from ..errors import ModelError
from .backend import gradient, jacobian


def derive_lagrangian(model, check_samples=8):
    """Return a dict with H, h, g, Q, rhs, dTdq, momentum_rate, E (see Dynamics).

    H = d2T/dqdot2 is checked free of velocities and time (T quadratic, scleronomic) and then
    checked numerically: T = 1/2 qdot^T H qdot and H positive definite at random states.
    h_j = sum_ik (dH_jk/dq_i - 1/2 dH_ik/dq_j) qdot_i qdot_k is assembled from the n matrices
    dH/dq_i computed once; no symbolic inverse, no global simplify.
    """
    q, qd = list(model.coords), list(model.velocities)
    n = len(q)
    qd_vec = sp.Matrix(qd)
    H = jacobian(gradient(model.T, qd), qd)
    H = sp.Matrix(n, n, lambda i, j: H[min(i, j), max(i, j)])   # exactly symmetric
    bad = sorted(str(s) for s in H.free_symbols & set(qd))
    if bad:
        raise ModelError(f"model {model.name}: T is not quadratic in the velocities "
                         f"(d2T/dqdot2 still depends on {', '.join(bad)})")
    _check_quadratic_and_definite(model, H, check_samples)

    # dH/dq_i for all i from one Jacobian of the upper triangle of H.
    upper = [(j, k) for j in range(n) for k in range(j, n)]
    dU = jacobian([H[j, k] for j, k in upper], q)
    dH = [sp.zeros(n, n) for _ in range(n)]
    for row, (j, k) in enumerate(upper):
        for i in range(n):
            dH[i][j, k] = dH[i][k, j] = dU[row, i]
    Hdot = sp.zeros(n, n)
    for i in range(n):
        Hdot += dH[i] * qd[i]
    dTdq = sp.Matrix([(qd_vec.T * dH[j] * qd_vec)[0, 0] / 2 for j in range(n)])
    h = Hdot * qd_vec - dTdq
    g = gradient(model.V, q)
    Q = sp.Matrix(model.forces) - gradient(model.dissipation, qd)
    return dict(H=H, h=h, g=g, Q=Q, rhs=Q - h - g, dTdq=dTdq, momentum_rate=dTdq - g + Q,
                E=model.T + model.V)


def sample_values(model):
    """Parameter values for numeric checks: defaults, or 1.0 where a value is required."""
    return [1.0 if d is None else d for d in model.defaults()]


def _check_quadratic_and_definite(model, H, samples):
    """Numeric checks at random states; they name the first state that fails."""
    if samples <= 0:
        return
    q, qd, params = list(model.coords), list(model.velocities), list(model.params)
    rng = np.random.default_rng(20261122)
    pvals = sample_values(model)
    f_H = sp.lambdify([q, params], H, modules="numpy")
    residual = model.T - (sp.Matrix(qd).T * H * sp.Matrix(qd))[0, 0] / 2
    f_res = sp.lambdify([q, qd, params], residual, modules="numpy")
    for _ in range(samples):
        qs = rng.uniform(-np.pi, np.pi, len(q))
        vs = rng.uniform(-1.0, 1.0, len(q))
        state = ", ".join(f"{c}={v:.3g}" for c, v in zip(q, qs))
        Hs = np.array(f_H(qs, pvals), dtype=float)
        scale = 1.0 + abs(f_res(qs, np.zeros(len(q)), pvals)) + np.abs(Hs).max()
        if abs(f_res(qs, vs, pvals)) > 1e-9 * scale:
            raise ModelError(f"model {model.name}: T is not a quadratic form in the velocities "
                             f"(T != 1/2 qdot^T H qdot at {state}); linear or velocity-free terms are not supported")
        try:
            np.linalg.cholesky(Hs)
        except np.linalg.LinAlgError:
            eig = np.linalg.eigvalsh(Hs)
            weakest = q[int(np.argmin(np.abs(np.diag(Hs))))]
            raise ModelError(f"model {model.name}: H = d2T/dqdot2 is not positive definite at {state} "
                             f"(smallest eigenvalue {eig.min():.3g}; check the terms in {weakest}.d)") from None
