"""Shared machinery of the constrained steppers (rattle, constrained_midpoint,
constrained_implicit_euler, spook, index1).

Equations of motion with m holonomic constraints (generated ``constraints`` kernel):

    H(q) qdd = rhs(q, v, t) + J(q)^T lam,    Phi(q) = 0,    J = dPhi/dq (m, n)

The ``extra`` buffer (see base.run_loop) holds, per run::

    extra[0:m]      lam, the constraint forces (multipliers) at the end of the last step
    extra[m]        max_i |Phi_i(q)|   at the end of the last step
    extra[m + 1]    max_i |(J v)_i|    at the end of the last step
    extra[m+2:]     scratch (see ``views``), not saved

The first m + 2 entries are saved with every output row (``extra_size`` gives (saved, total));
the saved lam is also the Newton initial guess of the next step, so a run continued in chunks
starts from the multiplier it stopped with. The driver fills row 0 (consistent lam0 and the
initial residuals, lagrange_gen.consistent).

Settings: the constrained methods read four more entries after base's N_SETTINGS (see
``make_constrained_settings``): spook's compliance epsilon and relaxation d, and index1's
Baumgarte coefficients alpha, beta.

Linear algebra: the augmented (KKT) systems [[A, -B^T], [C, 0]] are indefinite, and the int64
pivot array of base holds only n entries, so they are solved by Gaussian elimination with partial
pivoting applied to the right-hand side as it goes (``gauss_solve``, no pivot storage). The
velocity projections use the SPD Schur complement J H^-1 J^T (Cholesky).
"""

import numpy as np
from numba import njit

from ..linalg import SINGULAR_RTOL, cholesky_inplace, cholesky_solve_inplace
from ..status import OK, SINGULAR_MASS
from .base import FAST, N_SETTINGS, make_settings

# Settings entries after base's layout.
S_COMPLIANCE = N_SETTINGS          # spook: epsilon (compliance, 1/stiffness of Phi), >= 0
S_RELAXATION = N_SETTINGS + 1      # spook: d = tau / h (constraint damping time in steps), > 0
S_BAUMGARTE_ALPHA = N_SETTINGS + 2  # index1: Phi'' + 2 alpha Phi' + beta^2 Phi = 0
S_BAUMGARTE_BETA = N_SETTINGS + 3
N_CONSTRAINED_SETTINGS = N_SETTINGS + 4

#: Scratch after the m + 2 saved entries (see ``views``): one flag, _N_MVEC m-vectors, _N_MMAT
#: (m, n) matrices, then room for the largest augmented system b (big,), K (big, big).
_N_MVEC = 5
_N_MMAT = 4


def make_constrained_settings(newton_tol=1e-12, max_iter=50, bound=1e150, mode=0, compliance=0.0,
                              relaxation=2.0, baumgarte_alpha=0.0, baumgarte_beta=0.0):
    """The float64 settings array (N_CONSTRAINED_SETTINGS,) of the constrained methods."""
    base = make_settings(newton_tol, max_iter, bound, mode)
    more = np.array([compliance, relaxation, baumgarte_alpha, baumgarte_beta], dtype=np.float64)
    return np.concatenate((base, more))


@njit(inline="always")
def _layout(n, m):
    """Offsets in extra of the scratch parts: (flag, vectors, matrices, b, K, end)."""
    big = 2 * n + m         # the largest augmented system: rattle's (u, w, nu) for H(q)
    flag = m + 2
    vec = flag + 1
    mat = vec + _N_MVEC * m
    rhs = mat + _N_MMAT * m * n
    kkt = rhs + big
    return flag, vec, mat, rhs, kkt, kkt + big * big


@njit(cache=True)
def extra_size(n, m):
    """(saved, total) entries of the extra buffer for n coordinates and m constraints (callable
    from Python and from jitted code)."""
    return m + 2, _layout(n, m)[5]


@njit(inline="always")
def check_buffers(kern, q0, settings, out_extra, out_last):
    """Raise (instead of writing out of bounds) when a caller of run_<method> passes buffers
    too small for a constrained method: out_extra needs m + 2 columns, out_last 2n + 3 + total
    entries, settings N_CONSTRAINED_SETTINGS entries."""
    n, m = q0.shape[0], kern.N_CONSTRAINTS
    saved, total = extra_size(n, m)
    if m == 0:
        raise ValueError("constrained stepper called on a model without constraints")
    if out_extra.shape[1] < saved or out_last.shape[0] < 2 * n + 3 + total:
        raise ValueError("out_extra / out_last too small: see steppers.constrained.extra_size")
    if settings.shape[0] < N_CONSTRAINED_SETTINGS:
        raise ValueError("settings too short: use steppers.constrained.make_constrained_settings")


@njit(inline="always")
def flag_index(m):
    """Index in extra of a scratch flag that is 0.0 at the start of every run (run_loop zeroes
    the scratch): a method sets it once it has cached data from a previous step there."""
    return m + 2


@njit(inline="always")
def views(extra, n, m, size):
    """Views into the flat extra buffer (no allocation of data).

    lam (m,) saved multipliers; phi, gam, c1, c2, c3 (m,) scratch vectors; Ja, Jb, Y, T (m, n)
    scratch matrices (constraint Jacobians, H^-1 J^T rows); b (size,) and K (size, size) the
    right-hand side and matrix of an augmented system of the given size."""
    _, o, mat, rhs, kkt, _ = _layout(n, m)
    lam = extra[0:m]
    phi = extra[o:o + m]
    gam = extra[o + m:o + 2 * m]
    c1 = extra[o + 2 * m:o + 3 * m]
    c2 = extra[o + 3 * m:o + 4 * m]
    c3 = extra[o + 4 * m:o + 5 * m]
    Ja = extra[mat:mat + m * n].reshape((m, n))
    Jb = extra[mat + m * n:mat + 2 * m * n].reshape((m, n))
    Y = extra[mat + 2 * m * n:mat + 3 * m * n].reshape((m, n))
    T = extra[mat + 3 * m * n:mat + 4 * m * n].reshape((m, n))
    b = extra[rhs:rhs + size]
    K = extra[kkt:kkt + size * size].reshape((size, size))
    return lam, phi, gam, c1, c2, c3, Ja, Jb, Y, T, b, K


@njit(inline="always")
def schur_block(extra, n, m):
    """The (m, m) matrix at the place of K (for the velocity projections, after a Newton solve
    is done with K)."""
    kkt = _layout(n, m)[4]
    return extra[kkt:kkt + m * m].reshape((m, m))


@njit(cache=True, **FAST)
def gauss_solve(A, b):
    """Solve A x = b for A (N, N) by Gaussian elimination with partial pivoting; A is destroyed,
    b (N,) overwritten by x. Row swaps are applied to b as they happen, so no pivot array is
    needed. False when a pivot is below SINGULAR_RTOL times the largest entry of A."""
    N = A.shape[0]
    scale = 0.0
    for i in range(N):
        for j in range(N):
            scale = max(scale, abs(A[i, j]))
    if not (scale > 0.0) or scale == np.inf:
        return False
    for k in range(N):
        p = k
        big = abs(A[k, k])
        for i in range(k + 1, N):
            if abs(A[i, k]) > big:
                big = abs(A[i, k])
                p = i
        if not (big > SINGULAR_RTOL * scale):
            return False
        if p != k:
            for j in range(k, N):
                A[k, j], A[p, j] = A[p, j], A[k, j]
            b[k], b[p] = b[p], b[k]
        inv = 1.0 / A[k, k]
        for i in range(k + 1, N):
            f = A[i, k] * inv
            if f != 0.0:
                for j in range(k + 1, N):
                    A[i, j] -= f * A[k, j]
                b[i] -= f * b[k]
    for i in range(N - 1, -1, -1):
        s = b[i]
        for j in range(i + 1, N):
            s -= A[i, j] * b[j]
        b[i] = s / A[i, i]
    return True


@njit(cache=True, **FAST)
def phi_small(phi, J, q, tol):
    """Position-level stopping test: every constraint is within tol of its manifold, measured
    as a distance |Phi_i| / max_j |J_ij| relative to max(1, max|q|) (the scale of the Newton
    tests on velocities in base.newton_converged). Makes the test independent of how a user
    scales Phi (x^2 + y^2 - l^2 or its half)."""
    qs = 1.0
    for i in range(q.shape[0]):
        qs = max(qs, abs(q[i]))
    for i in range(phi.shape[0]):
        g = 0.0
        for j in range(J.shape[1]):
            g = max(g, abs(J[i, j]))
        if not (abs(phi[i]) <= tol * qs * g):
            return False
    return True


@njit(cache=True, **FAST)
def max_abs_jv(J, v):
    """max_i |(J v)_i| for J (m, n), v (n,); NaN propagates."""
    r = 0.0
    for i in range(J.shape[0]):
        s = 0.0
        for j in range(J.shape[1]):
            s += J[i, j] * v[j]
        a = abs(s)
        if a > r or a != a:
            r = a
    return r


@njit(cache=True, **FAST)
def record(extra, m, phi, J, v):
    """Store max|Phi| and max|J v| of the end-of-step state in the saved part of extra."""
    r = 0.0
    for i in range(m):
        a = abs(phi[i])
        if a > r or a != a:
            r = a
    extra[m] = r
    extra[m + 1] = max_abs_jv(J, v)


@njit(cache=True, **FAST)
def solve_rows(L, J, Y):
    """Y_k = H^-1 J_k^T for every row k of J (m, n), with L the Cholesky factor of H (n, n)."""
    for k in range(J.shape[0]):
        for j in range(J.shape[1]):
            Y[k, j] = J[k, j]
        cholesky_solve_inplace(L, Y[k])


@njit(cache=True, **FAST)
def project(J, Y, x, S, eta):
    """Project x (n,) onto J x = 0 in the metric of H: x <- x + Y^T eta with Y = H^-1 J^T rows
    (from ``solve_rows``) and eta (m,) solving (J H^-1 J^T) eta = -J x. S (m, m) is scratch.
    Returns False when J H^-1 J^T is singular (rank-deficient J: redundant constraints)."""
    m, n = J.shape
    for i in range(m):
        s = 0.0
        for j in range(n):
            s -= J[i, j] * x[j]
        eta[i] = s
        for k in range(m):
            s = 0.0
            for j in range(n):
                s += J[i, j] * Y[k, j]
            S[i, k] = s
    if not cholesky_inplace(S):
        return False
    cholesky_solve_inplace(S, eta)
    for k in range(m):
        for j in range(n):
            x[j] += Y[k, j] * eta[k]
    return True


@njit(**FAST)
def velocity_projection(kern, q1, p, J, Y, H, S, eta, v1, from_momentum):
    """Velocity stage shared by the projected methods, at q1 (already on Phi = 0) with
    J = J(q1) (m, n): v1 <- v1 + H(q1)^-1 J^T eta with J v1 = 0 afterwards, i.e. the projection
    closest in the kinetic-energy metric. With from_momentum, v1 holds a momentum pt on entry and
    is first mapped to H(q1)^-1 pt, so that pt + J^T eta is the projected momentum.

    Y (m, n), H (n, n), S (m, m) are scratch; eta (m,) receives the momentum impulse.
    Status OK or SINGULAR_MASS (H(q1) or J H^-1 J^T singular)."""
    kern.mass_matrix(q1, p, H)
    if not cholesky_inplace(H):
        return SINGULAR_MASS
    if from_momentum:
        cholesky_solve_inplace(H, v1)
    solve_rows(H, J, Y)
    if not project(J, Y, v1, S, eta):
        return SINGULAR_MASS
    return OK
