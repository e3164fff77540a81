"""H, h (Christoffel form), g, Q, energy: the unconstrained Lagrangian part, in native objects."""

from __future__ import annotations

import numpy as np

from ..errors import ModelError
from .backend import Mat


def derive_lagrangian(model, o, check_samples=8):
    """Return a dict of native objects: H (n, n); h, g, Q, rhs, dTdq, momentum_rate (n, 1);
    E; and dH, the list of the n matrices dH/dq_i (n, n), for the Jacobians.

    H = d2T/dqdot2 is checked free of velocities and time (T quadratic, scleronomic) and then
    checked numerically: T = 1/2 qdot^T H qdot and H positive definite at random states.
    h_j = sum_ik (dH_jk/dq_i - 1/2 dH_ik/dq_j) qdot_i qdot_k is assembled from the n matrices
    dH/dq_i computed once, as h = Hdot qdot - dT/dq with Hdot_jk = sum_i dH_jk/dq_i qdot_i kept
    as a nested sum (never expanded): no symbolic inverse, no global simplify.
    """
    q, qd = o.symbols(model.coords), o.symbols(model.velocities)
    n = len(q)
    T, V = o.native(model.T), o.native(model.V)
    H = _mass_matrix(model, o, T, qd)
    _check_quadratic_and_definite(model, o, H, T, check_samples)
    dH = [o.matrix(n, n, [H[j, k].diff(qi) for j in range(n) for k in range(n)]) for qi in q]
    zero = o.native(0)
    Hdot = o.matrix(n, n, [_dot([dH[i][j, k] for i in range(n)], qd, zero)
                           for j in range(n) for k in range(n)])
    dTdq = [_quadratic(dH[j], qd, zero) / 2 for j in range(n)]
    h = [_dot([Hdot[j, k] for k in range(n)], qd, zero) - dTdq[j] for j in range(n)]
    g = [V.diff(qi) for qi in q]
    D = o.native(model.dissipation)
    Q = [o.native(f) - D.diff(v) for f, v in zip(model.forces, qd)]
    col = o.column
    return dict(H=H, h=col(h), g=col(g), Q=col(Q), rhs=col([Q[j] - h[j] - g[j] for j in range(n)]),
                dTdq=col(dTdq), momentum_rate=col([dTdq[j] - g[j] + Q[j] for j in range(n)]),
                E=T + V, dH=dH, Hdot=Hdot)


def _mass_matrix(model, o, T, qd):
    """H = d2T/dqdot2 (n, n), exactly symmetric (upper triangle mirrored); ModelError if it
    still depends on a velocity."""
    n = len(qd)
    grad = [T.diff(v) for v in qd]
    upper = {(j, k): grad[j].diff(qd[k]) for j in range(n) for k in range(j, n)}
    H = o.matrix(n, n, [upper[min(j, k), max(j, k)] for j in range(n) for k in range(n)])
    names = {s.name for s in model.velocities}
    bad = sorted(str(s) for s in H.free_symbols if str(s) in names)
    if bad:
        raise ModelError(f"model {model.name}: T is not quadratic in the velocities "
                         f"(d2T/dqdot2 still depends on {', '.join(bad)})")
    return H


def _sum(terms, zero):
    return sum(terms[1:], terms[0]) if terms else zero


def _dot(coeffs, vec, zero):
    """sum_i coeffs_i vec_i over the nonzero coefficients (structural zeros skipped)."""
    return _sum([c * v for c, v in zip(coeffs, vec) if c != 0], zero)


def _quadratic(M: Mat, vec, zero):
    """vec^T M vec for symmetric M, summing the upper triangle once (off-diagonal doubled)."""
    n = len(vec)
    terms = []
    for i in range(n):
        if M[i, i] != 0:
            terms.append(M[i, i] * vec[i] ** 2)
        for k in range(i + 1, n):
            if M[i, k] != 0:
                terms.append(2 * M[i, k] * vec[i] * vec[k])
    return _sum(terms, zero)


def sample_values(model):
    """Parameter values for numeric checks: defaults, or 1.0 where a value is required."""
    return [1.0 if d is None else d for d in model.defaults()]


def _check_quadratic_and_definite(model, o, H, T, samples):
    """Numeric checks at random states; they name the first state that fails. T and H are
    evaluated separately (no symbolic qdot^T H qdot, which costs n^2 products)."""
    if samples <= 0:
        return
    n = len(model.coords)
    args = o.symbols(list(model.coords) + list(model.velocities) + list(model.params))
    f_T, f_H = o.lambdify(args, [T]), o.lambdify(args, list(H))
    rng = np.random.default_rng(20261122)
    pvals = sample_values(model)
    for _ in range(samples):
        qs, vs = rng.uniform(-np.pi, np.pi, n), rng.uniform(-1.0, 1.0, n)
        state = ", ".join(f"{c}={v:.3g}" for c, v in zip(model.coords, qs))
        Hs = np.asarray(f_H([*qs, *vs, *pvals]), dtype=float).reshape(n, n)
        t_rest = f_T([*qs, *np.zeros(n), *pvals])[0]
        scale = 1.0 + abs(t_rest) + np.abs(Hs).max()
        if abs(f_T([*qs, *vs, *pvals])[0] - vs @ Hs @ vs / 2) > 1e-9 * scale:
            raise ModelError(f"model {model.name}: T is not a quadratic form in the velocities "
                             f"(T != 1/2 qdot^T H qdot at {state}); linear or velocity-free terms are not supported")
        try:
            np.linalg.cholesky(Hs)
        except np.linalg.LinAlgError:
            eig, vectors = np.linalg.eigh(Hs)
            raise ModelError(f"model {model.name}: H = d2T/dqdot2 is not positive definite at {state} "
                             f"(smallest eigenvalue {eig[0]:.3g}; check the terms in "
                             f"{_weakest_direction(model.coords, vectors[:, 0])})") from None


def _weakest_direction(coords, vector):
    """"y.d, x.d": the velocities along which T is not positive, i.e. the largest components
    (at least half the largest) of the eigenvector (n,) of H's smallest eigenvalue, largest
    first. A sign error in one term of T shows there, not in the smallest diagonal entry."""
    size = np.abs(vector)
    order = np.argsort(-size, kind="stable")
    return ", ".join(f"{coords[i]}.d" for i in order if size[i] >= 0.5 * size.max())
