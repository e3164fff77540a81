"""H, h (Christoffel form), g, Q, energy: the unconstrained Lagrangian part, in native objects."""

from __future__ import annotations

import numpy as np

from .backend import Mat
from ..errors import ModelError
from ..model.symbols import t


def derive_lagrangian(model, o, check_samples=8):
    """Return a dict of native objects: H (n, n); h, g, Q, rhs, dTdq, momentum_rate (n, 1);
    E; dH, the list of the n matrices dH/dq_i (n, n); Hdot and Ht = dH/dt (n, n) or None.

    T is split by degree in the velocities, T = T2 + T1 + T0 (rheonomic systems, rotating
    frames; MEAM 535 notes, ../shared/sources/002): H = d2T/dqdot2 (T2 = 1/2 qdot^T H qdot),
    b = dT/dqdot at qdot = 0 (T1 = b . qdot), T0 = T at qdot = 0. H is checked free of velocities
    and then, numerically, T = T2 + T1 + T0 and H positive definite at random (q, qdot, t).
    Lagrange's equations d/dt(H qdot + b) - dL/dq = Q with L = T2 + T1 + T0 - V become
    H qddot + h + g = Q with
      h_j = sum_ik (dH_jk/dq_i - 1/2 dH_ik/dq_j) qdot_i qdot_k + (dH/dt qdot)_j,
      g = d(V - T0)/dq                       (T0 acts in the effective potential V - T0),
      Q_j += sum_k (db_k/dq_j - db_j/dq_k) qdot_k - db_j/dt   (gyroscopic and transport terms).
    h is assembled from the n matrices dH/dq_i computed once, as h = Hdot qdot - dT2/dq (+ Ht
    qdot) with Hdot_jk = sum_i dH_jk/dq_i qdot_i kept as a nested sum (never expanded): no
    symbolic inverse, no global simplify. E is the energy function (Jacobi integral)
    T2 - T0 + V, which is T + V for a scleronomic T and is conserved when L has no explicit t.
    In rhs the T1 terms are generalized forces (in Q). The momentum-form steppers use the
    canonical momentum p = dL/dqdot = H qdot + b (so that the variational methods stay
    variational with gyroscopic terms): momentum_rate = dp/dt = dL/dq + Q_nc
    = dT2/dq + (db/dq)^T qdot - g + Q_nc, and b, db/dq (n, n) are returned as b, db.
    power (2n + 2, 1) = (P, dP/dq, dP/dqdot, dP/dt) with P = qdot . Q_nc - dL/dt = dE/dt, the
    rate of the work W that closes the energy balance E - E0 - W = 0.
    """
    q, qd = o.symbols(model.coords), o.symbols(model.velocities)
    time = o.native(t)
    n = len(q)
    T, V = o.native(model.T), o.native(model.V)
    H = _mass_matrix(model, o, T, qd)
    at_rest = {v: 0 for v in qd}
    T0 = T.subs(at_rest)
    b = [T.diff(v).subs(at_rest) for v in qd]
    _check_quadratic_and_definite(model, o, H, T, b, T0, check_samples)
    dH = [o.matrix(n, n, [H[j, k].diff(qi) for j in range(n) for k in range(n)]) for qi in q]
    zero = o.native(0)
    Hdot = o.matrix(n, n, [dot([dH[i][j, k] for i in range(n)], qd, zero)
                           for j in range(n) for k in range(n)])
    Ht = o.matrix(n, n, [H[j, k].diff(time) for j in range(n) for k in range(n)])
    Ht = Ht if any(e != 0 for e in Ht) else None
    dTdq = [quadratic_form(dH[j], qd, zero) / 2 for j in range(n)]
    h = [dot([Hdot[j, k] for k in range(n)], qd, zero) - dTdq[j] for j in range(n)]
    if Ht is not None:
        h = [h[j] + dot([Ht[j, k] for k in range(n)], qd, zero) for j in range(n)]
    g = [(V - T0).diff(qi) if T0 != 0 else V.diff(qi) for qi in q]
    D = o.native(model.dissipation)
    Q = [o.native(f) - D.diff(v) for f, v in zip(model.forces, qd)]
    Q_nc = Q
    Q = [Q[j] + _transport_force(b, q, qd, j, time, zero) for j in range(n)]
    db = o.matrix(n, n, [b[j].diff(q[k]) for j in range(n) for k in range(n)])
    mom = [dTdq[j] - g[j] + Q_nc[j] + dot([db[k, j] for k in range(n)], qd, zero) for j in range(n)]
    col = o.column
    P = dot(Q_nc, qd, zero) - (T - V).diff(time)
    power = [P, *(P.diff(v) for v in q), *(P.diff(v) for v in qd), P.diff(time)]
    E = T + V
    if T0 != 0 or any(bj != 0 for bj in b):
        E = quadratic_form(H, qd, zero) / 2 - T0 + V
    return dict(H=H, h=col(h), g=col(g), Q=col(Q), rhs=col([Q[j] - h[j] - g[j] for j in range(n)]),
                dTdq=col(dTdq), momentum_rate=col(mom), E=E, dH=dH, Hdot=Hdot, Ht=Ht,
                b=col(b), db=db, power=col(power))


def _transport_force(b, q, qd, j, time, zero):
    """The generalized force of T1 = b(q, t) . qdot on coordinate j:
    sum_k (db_k/dq_j - db_j/dq_k) qdot_k - db_j/dt (zero terms skipped)."""
    if all(bk == 0 for bk in b):
        return zero
    terms = [b[k].diff(q[j]) - b[j].diff(q[k]) for k in range(len(q))]
    return dot(terms, qd, zero) - b[j].diff(time)


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


def dot(coeffs, vec, zero):
    """sum_i coeffs_i vec_i over the nonzero coefficients (structural zeros skipped)."""
    return _sum([c * v for c, v in zip(coeffs, vec) if c != 0], zero)


def quadratic_form(M: Mat, vec, zero):
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


def _check_quadratic_and_definite(model, o, H, T, b, T0, samples):
    """Numeric checks at random (q, qdot, t); they name the first state that fails. T, H, b and
    T0 are evaluated separately (no symbolic qdot^T H qdot, which costs n^2 products): T must
    equal 1/2 qdot^T H qdot + b . qdot + T0 (nothing of degree > 2 in the velocities)."""
    if samples <= 0:
        return
    n = len(model.coords)
    args = o.symbols(list(model.coords) + list(model.velocities) + list(model.params) + [t])
    f_T, f_H, f_b = o.lambdify(args, [T, T0]), o.lambdify(args, list(H)), o.lambdify(args, b)
    rng = np.random.default_rng(20261122)
    pvals = sample_values(model)
    for _ in range(samples):
        qs, vs, ts = rng.uniform(-np.pi, np.pi, n), rng.uniform(-1.0, 1.0, n), rng.uniform(0.0, 2.0)
        state = ", ".join(f"{c}={v:.3g}" for c, v in zip(model.coords, qs))
        Hs = np.asarray(f_H([*qs, *vs, *pvals, ts]), dtype=float).reshape(n, n)
        T_at, T0_at = f_T([*qs, *vs, *pvals, ts])
        bs = f_b([*qs, *vs, *pvals, ts])
        scale = 1.0 + abs(T0_at) + np.abs(bs).sum() + np.abs(Hs).max()
        if abs(T_at - vs @ Hs @ vs / 2 - bs @ vs - T0_at) > 1e-9 * scale:
            raise ModelError(f"model {model.name}: T is not of degree <= 2 in the velocities "
                             f"(T != T2 + T1 + T0 with T2 = 1/2 qdot^T H qdot at {state})")
        try:
            np.linalg.cholesky(Hs)
        except np.linalg.LinAlgError:
            eig, vectors = np.linalg.eigh(Hs)
            at_start = _time_where_definite(f_H, qs, vs, pvals, n)
            if at_start is not None:
                raise ModelError(
                    f"model {model.name}: H = d2T/dqdot2 depends on t and is not positive definite "
                    f"at t = {ts:.3g} ({state}; smallest eigenvalue {eig[0]:.3g}), though it is at "
                    f"t = {at_start:g}: the time-dependent terms of T must keep it positive for "
                    f"every t (checked for t in [0, 2])") from None
            raise ModelError(f"model {model.name}: H = d2T/dqdot2 is not positive definite at {state} "
                             f"(smallest eigenvalue {eig[0]:.3g}; check the terms in "
                             f"{weakest_direction(model.coords, vectors[:, 0])})") from None


def _time_where_definite(f_H, qs, vs, pvals, n):
    """A time of [0, 2] at which H (n, n) at the same q is positive definite (so that what fails
    at another time is the time dependence), or None."""
    for time in (0.0, 0.5, 1.0, 1.5, 2.0):
        try:
            np.linalg.cholesky(np.asarray(f_H([*qs, *vs, *pvals, time]), dtype=float).reshape(n, n))
            return time
        except np.linalg.LinAlgError:
            continue
    return None


def weakest_direction(coords, vector):
    """"y.d, x.d": the velocities along which T is not positive, i.e. the largest components
    (at least half the largest) of the eigenvector (n,) of H's smallest eigenvalue, largest
    first. A sign error in one term of T shows there, not in the smallest diagonal entry."""
    size = np.abs(vector)
    order = np.argsort(-size, kind="stable")
    return ", ".join(f"{coords[i]}.d" for i in order if size[i] >= 0.5 * size.max())
