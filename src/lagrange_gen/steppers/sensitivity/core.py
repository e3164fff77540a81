"""The forward-sensitivity loop and the tangent algebra the methods' tangent steps share.

The tangent of the state is S = d(q, v)/d theta (2n, c): c columns, the first k for parameters
(entries cols[j] of p), then those of q0 and v0 as asked. A tangent step maps the S of the start
of a step to the S of its end by the exact derivative of the step the method took (its own
Newton solutions, read from its workspace): S_q, S_v (n, c) views of S, S_m (n, c) the tangent
of the momentum a momentum-form method carries (or of verlet's cached acceleration).

Every array is allocated once, in ``sensitivity_loop`` before its first step (``workspace``);
the helpers write into views of it. The parameter columns of a derivative kernel (n, n_params)
enter as ``add_parameter_columns``.
"""

from collections import namedtuple

import numpy as np

from ...jit.cache import njit
from ..core import linalg
from ..core.options import FAST
from ..core.status import NON_FINITE, OK, SINGULAR_MASS, SINGULAR_NEWTON

#: Scratch of one sensitivity run: the state at the start of a step (q0, v0, m0), the tangents
#: S (2n, c) and Sm (n, c), matrices H, A (factored), Jq, Jqd, D, Jb (n, n), parameter Jacobians
#: Jp, Jp2, Jbp (n, n_params), vectors rhs, a, work (n,), pivots, tangent temporaries T1..T3
#: (n, c), and rk4's stage tangents dV, dA (4, n, c) with the stage coordinates Qs (n,).
Workspace = namedtuple("Workspace", "q0 v0 m0 S Sm H A piv Jq Jqd D Jb Jp Jp2 Jbp rhs a work "
                                    "col T1 T2 T3 dV dA Qs")


@njit
def workspace(n, c, n_params):
    """Allocated once per run by sensitivity_loop."""
    return Workspace(np.zeros(n), np.zeros(n), np.zeros(n), np.zeros((2 * n, c)),
                     np.zeros((n, c)), np.zeros((n, n)), np.zeros((n, n)),
                     np.zeros(n, np.int64), np.zeros((n, n)), np.zeros((n, n)),
                     np.zeros((n, n)), np.zeros((n, n)), np.zeros((n, n_params)),
                     np.zeros((n, n_params)), np.zeros((n, n_params)),
                     np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n),
                     np.zeros((n, c)), np.zeros((n, c)), np.zeros((n, c)),
                     np.zeros((4, n, c)), np.zeros((4, n, c)), np.zeros(n))


@njit(**FAST)
def matmul_add(A, X, out, scale, n):
    """out (n, c) += scale * A (n, n) @ X (n, c)."""
    c = X.shape[1]
    for i in range(n):
        for k in range(n):
            a = scale * A[i, k]
            if a != 0.0:
                for j in range(c):
                    out[i, j] += a * X[k, j]


@njit(**FAST)
def add_parameter_columns(Jp, cols, out, scale, n):
    """out[:, j] += scale * Jp[:, cols[j]] for the parameter columns j < len(cols)."""
    for j in range(cols.shape[0]):
        col = cols[j]
        for i in range(n):
            out[i, j] += scale * Jp[i, col]


@njit(**FAST)
def set_zero(X):
    for i in range(X.shape[0]):
        for j in range(X.shape[1]):
            X[i, j] = 0.0


@njit(**FAST)
def copy_matrix(dst, src):
    for i in range(src.shape[0]):
        for j in range(src.shape[1]):
            dst[i, j] = src[i, j]


@njit(**FAST)
def factor(A, piv):
    """LU factors of A (n, n) in place; False when singular."""
    return linalg.lu_inplace(A, piv)


@njit(**FAST)
def solve_columns(LU, piv, X, col, work, n):
    """X (n, c) <- A^-1 X from A's LU factors (column by column through col (n,))."""
    for j in range(X.shape[1]):
        for i in range(n):
            col[i] = X[i, j]
        linalg.lu_solve_inplace(LU, piv, col, work)
        for i in range(n):
            X[i, j] = col[i]


@njit(**FAST)
def acceleration_tangent(kern, q, v, t, p, cols, Sq, Sv, out, tw):
    """out (n, c) = da = a_q Sq + a_v Sv + a_p E for a = H(q)^-1 rhs(q, v, t):
    H da = (d rhs/dq - d(H a)/dq) Sq + d rhs/dv Sv + (d rhs/dp - d(H a)/dp) E. Leaves a in
    tw.a. Returns OK or SINGULAR_MASS."""
    n = kern.N_COORDS
    H, A, a = tw.H, tw.A, tw.a
    kern.dynamics(q, v, t, p, H, tw.rhs)
    copy_matrix(A, H)
    if not factor(A, tw.piv):
        return SINGULAR_MASS
    for i in range(n):
        a[i] = tw.rhs[i]
    linalg.lu_solve_inplace(A, tw.piv, a, tw.work)
    kern.rhs_jacobian(q, v, t, p, tw.Jq, tw.Jqd)
    kern.mass_matvec_dq(q, a, t, p, tw.D)
    set_zero(out)
    matmul_add(tw.Jq, Sq, out, 1.0, n)
    matmul_add(tw.D, Sq, out, -1.0, n)
    matmul_add(tw.Jqd, Sv, out, 1.0, n)
    if cols.shape[0]:
        kern.rhs_dp(q, v, t, p, tw.Jp)
        kern.mass_matvec_dp(q, a, t, p, tw.Jp2)
        add_parameter_columns(tw.Jp, cols, out, 1.0, n)
        add_parameter_columns(tw.Jp2, cols, out, -1.0, n)
    solve_columns(A, tw.piv, out, tw.col, tw.work, n)
    return OK


@njit(**FAST)
def transport_tangent(kern, q, t, p, cols, Sq, out, scale, tw):
    """out (n, c) += scale * d b(q, t) = scale * (db/dq Sq + db/dp E) on a model with a T1 =
    b . v term in T (the canonical momentum H v + b; nothing otherwise). Leaves db/dq in tw.Jb
    (the callers' Newton matrices gain it)."""
    if kern.TRANSPORT:
        n = kern.N_COORDS
        for i in range(n):
            for j in range(n):
                tw.Jb[i, j] = 0.0
        kern.transport_dq(q, t, p, tw.Jb)          # accumulates: out_mat += db/dq
        matmul_add(tw.Jb, Sq, out, scale, n)
        if cols.shape[0]:
            kern.transport_dp(q, t, p, tw.Jbp)
            add_parameter_columns(tw.Jbp, cols, out, scale, n)


@njit(**FAST)
def momentum_tangent(kern, q, v, t, p, cols, Sq, Sv, out, tw):
    """out (n, c) = d(H(q) v + b(q)) = (D(q; v) + db/dq) Sq + H Sv + d(H v + b)/dp E (the
    momentum's tangent)."""
    n = kern.N_COORDS
    kern.mass_matrix(q, t, p, tw.H)
    kern.mass_matvec_dq(q, v, t, p, tw.D)
    set_zero(out)
    matmul_add(tw.D, Sq, out, 1.0, n)
    matmul_add(tw.H, Sv, out, 1.0, n)
    if cols.shape[0]:
        kern.mass_matvec_dp(q, v, t, p, tw.Jp2)
        add_parameter_columns(tw.Jp2, cols, out, 1.0, n)
    transport_tangent(kern, q, t, p, cols, Sq, out, 1.0, tw)


@njit(**FAST)
def velocity_tangent(kern, q, v, t, p, cols, Sq, Sm, Sv, tw):
    """Sv (n, c) from v = H(q)^-1 (m - b(q)): H Sv = Sm - D(q; v) Sq - d(H v)/dp E - d b.
    Returns OK or SINGULAR_MASS."""
    n = kern.N_COORDS
    kern.mass_matrix(q, t, p, tw.A)
    kern.mass_matvec_dq(q, v, t, p, tw.D)
    copy_matrix(Sv, Sm)
    matmul_add(tw.D, Sq, Sv, -1.0, n)
    if cols.shape[0]:
        kern.mass_matvec_dp(q, v, t, p, tw.Jp2)
        add_parameter_columns(tw.Jp2, cols, Sv, -1.0, n)
    transport_tangent(kern, q, t, p, cols, Sq, Sv, -1.0, tw)
    if not factor(tw.A, tw.piv):
        return SINGULAR_MASS
    solve_columns(tw.A, tw.piv, Sv, tw.col, tw.work, n)
    return OK


@njit(**FAST)
def momentum_tangent_rhs(kern, q, u, t, hk, p, cols, Sq, Sm, out, tw):
    """The right-hand side of the tangent of a momentum update H(q) u + b(q) = m + hk f(q, u, t):
    out (n, c) = Sm - (D(q; u) - hk f_q) Sq - (d(H u)/dp - hk f_p) E - d b. Leaves H(q) in
    tw.H, D(q; u) = d(H u)/dq in tw.D and f_q, f_v in tw.Jq, tw.Jqd (the callers' matrices)."""
    n = kern.N_COORDS
    kern.mass_matrix(q, t, p, tw.H)
    kern.mass_matvec_dq(q, u, t, p, tw.D)
    kern.momentum_rate_jacobian(q, u, t, p, tw.Jq, tw.Jqd)
    copy_matrix(out, Sm)
    matmul_add(tw.D, Sq, out, -1.0, n)
    matmul_add(tw.Jq, Sq, out, hk, n)
    if cols.shape[0]:
        kern.mass_matvec_dp(q, u, t, p, tw.Jp2)
        kern.momentum_rate_dp(q, u, t, p, tw.Jp)
        add_parameter_columns(tw.Jp2, cols, out, -1.0, n)
        add_parameter_columns(tw.Jp, cols, out, hk, n)
    transport_tangent(kern, q, t, p, cols, Sq, out, -1.0, tw)


@njit(**FAST)
def kick_tangent(kern, q, u, t, hk, p, cols, Sq, Sm, du, tw):
    """The kick H(q) u + b(q) = m + hk f(q, u, t) at its solution u: du (n, c) from
    (H - hk f_v) du = momentum_tangent_rhs. Leaves H(q) in tw.H and D(q; u) in tw.D (the
    caller's d(H(q) u + b), with momentum_columns). Returns OK or SINGULAR_NEWTON."""
    n = kern.N_COORDS
    momentum_tangent_rhs(kern, q, u, t, hk, p, cols, Sq, Sm, du, tw)
    for i in range(n):
        for j in range(n):
            tw.A[i, j] = tw.H[i, j] - hk * tw.Jqd[i, j]
    if not factor(tw.A, tw.piv):
        return SINGULAR_NEWTON
    solve_columns(tw.A, tw.piv, du, tw.col, tw.work, n)
    return OK


@njit(**FAST)
def finite(x):
    for i in range(x.shape[0]):
        if not np.isfinite(x[i]):
            return False
    return True


@njit(**FAST)
def finite_matrix(X):
    for i in range(X.shape[0]):
        for j in range(X.shape[1]):
            if not np.isfinite(X[i, j]):
                return False
    return True


@njit(**FAST)
def save(row, kern, q, v, t, p, S, iters, resid, out_q, out_v, out_S, out_stats):
    n = kern.N_COORDS
    for i in range(n):
        out_q[row, i] = q[i]
        out_v[row, i] = v[i]
    copy_matrix(out_S[row], S)
    out_stats[row, 0] = kern.energy(q, v, t, p)
    out_stats[row, 1] = iters
    out_stats[row, 2] = resid


@njit
def sensitivity_loop(method, tangent, kern, q0, v0, t0, h, n_steps, save_every, p, settings,
                     cols, S0, out_q, out_v, out_S, out_stats):
    """Run ``method`` (its prepare and step) from (q0, v0) at t0 for n_steps steps of h, and
    ``tangent`` (steppers/sensitivity/<method>.py: prepare, step) beside it from S0 (2n, c).

    Saves rows 0, every save_every-th step and the last step: out_q, out_v (S, n), out_S
    (S, 2n, c), out_stats (S, 3) = (energy, Newton iterations since the last save, largest
    Newton residual since then). Returns (status, steps done): OK, or the method's failure
    status, NON_FINITE for a non-finite state or tangent, at the step that failed."""
    n = kern.N_COORDS
    q, v, mom = q0.copy(), v0.copy(), np.zeros(n)
    extra = np.zeros(0)
    ws = method.workspace(kern, n)
    tw = workspace(n, S0.shape[1], p.shape[0])
    copy_matrix(tw.S, S0)
    status = method.prepare(kern, q, v, mom, t0, p, settings, ws, extra)
    if status != OK:
        return status, -1
    status = tangent.prepare(kern, q, v, t0, p, settings, ws, tw, cols)
    if status != OK:
        return status, -1
    save(0, kern, q, v, t0, p, tw.S, 0.0, 0.0, out_q, out_v, out_S, out_stats)
    row, iters, resid = 0, 0.0, 0.0
    for k in range(n_steps):
        t = t0 + k * h       # as run_loop: not accumulated
        for i in range(n):
            tw.q0[i], tw.v0[i], tw.m0[i] = q[i], v[i], mom[i]
        status, it, res = method.step(kern, q, v, mom, t, h, p, settings, ws, extra)
        if status != OK:
            return status, k
        status = tangent.step(kern, tw.q0, tw.v0, q, v, t, h, p, settings, ws, tw, cols)
        if status != OK:
            return status, k
        if not (finite(q) and finite(v) and finite_matrix(tw.S)):
            return NON_FINITE, k
        iters += it
        resid = max(resid, res)
        if (k + 1) % save_every == 0 or k + 1 == n_steps:
            row += 1
            save(row, kern, q, v, t0 + (k + 1) * h, p, tw.S, iters, resid, out_q, out_v, out_S,
                 out_stats)
            iters, resid = 0.0, 0.0
    return OK, n_steps
