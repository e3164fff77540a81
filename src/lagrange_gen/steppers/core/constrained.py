"""Shared machinery of the constrained steppers (rattle, constrained_midpoint,
constrained_implicit_euler, spook, index1).

Equations of motion with m holonomic constraints (generated ``constraints`` kernel):

    H(q) qdd = rhs(q, v, t) + J(q)^T lam,    Phi(q, t) = 0,    J = dPhi/dq (m, n)

and the velocity constraint J v + dPhi/dt = 0 (generated ``constraint_rate``; dPhi/dt is zero,
and not evaluated, when the constraints are scleronomic, kern.CONSTRAINTS_RHEONOMIC False).

Every constrained method saves the same fields (SPEC.saved), so its ``extra`` buffer (see
run_loop.run_loop) is, with m = kern.N_CONSTRAINTS::

    extra[0:m]      lam, the constraint forces (multipliers) at the end of the last step
    extra[m]        max_i |Phi_i(q)|   at the end of the last step
    extra[m + 1]    max_i |(J v + dPhi/dt)_i|    at the end of the last step

The saved lam is also the Newton initial guess of the next step, so a run continued in chunks
starts from the multiplier it stopped with. The driver fills row 0 (consistent lam0 and the
initial residuals, lagrange_gen.run.consistent). Scratch lives in each method's workspace.

Linear algebra: the augmented (KKT) systems [[A, -B^T], [C, 0]] of the Newton iterations are
indefinite and go through newton.solve (LU with partial pivoting, solve.newton_solve). The
velocity projections use the SPD Schur complement J H^-1 J^T (Cholesky).
"""

from ...jit.cache import njit

from .legendre import subtract_transport

from .options import FAST
from .linalg import cholesky_inplace, cholesky_solve_inplace
from .status import OK, SINGULAR_MASS

#: The saved fields of every constrained method (its SPEC.saved), the layout above.
SAVED = (("multipliers", "m"), ("constraint_error", 1), ("velocity_constraint_error", 1))


@njit(**FAST)
def constraint_rate(kern, q, t, p, rate):
    """rate (m,) <- dPhi/dt at (q, t): the generated kernel for rheonomic constraints, zeros
    otherwise (no call)."""
    if kern.CONSTRAINTS_RHEONOMIC:
        kern.constraint_rate(q, t, p, rate)
    else:
        for i in range(rate.shape[0]):
            rate[i] = 0.0


@njit(cache=True, **FAST)
def max_abs_jv(J, v, rate):
    """max_i |(J v + rate)_i| for J (m, n), v (n,), rate (m,) (dPhi/dt); NaN propagates."""
    r = 0.0
    for i in range(J.shape[0]):
        s = rate[i]
        for j in range(J.shape[1]):
            s += J[i, j] * v[j]
        a = abs(s)
        if a > r or a != a:
            r = a
    return r


@njit(cache=True, **FAST)
def record(extra, m, phi, J, v, rate):
    """Store max|Phi| and max|J v + dPhi/dt| (rate (m,) = dPhi/dt) of the end-of-step state in
    the saved part of extra."""
    r = 0.0
    for i in range(m):
        a = abs(phi[i])
        if a > r or a != a:
            r = a
    extra[m] = r
    extra[m + 1] = max_abs_jv(J, v, rate)


@njit(cache=True, **FAST)
def solve_rows(L, J, Y):
    """Y_k = H^-1 J_k^T for every row k of J (m, n), with L the Cholesky factor of H (n, n)."""
    for k in range(J.shape[0]):
        for j in range(J.shape[1]):
            Y[k, j] = J[k, j]
        cholesky_solve_inplace(L, Y[k])


@njit(cache=True, **FAST)
def project(J, Y, x, S, eta, rate):
    """Project x (n,) onto J x + rate = 0 in the metric of H: x <- x + Y^T eta with Y = H^-1 J^T
    rows (from ``solve_rows``) and eta (m,) solving (J H^-1 J^T) eta = -(J x + rate); rate (m,)
    is dPhi/dt (zero for scleronomic constraints). S (m, m) is scratch.
    Returns False when J H^-1 J^T is singular (rank-deficient J: redundant constraints)."""
    m, n = J.shape
    for i in range(m):
        s = -rate[i]
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
def velocity_projection(kern, q1, t1, p, J, Y, H, S, eta, v1, from_momentum, rate):
    """Velocity stage shared by the projected methods, at q1 (already on Phi(q1, t1) = 0) with
    J = J(q1, t1) (m, n) and rate = dPhi/dt there (m,): v1 <- v1 + H(q1)^-1 J^T eta with
    J v1 + rate = 0 afterwards, i.e. the projection
    closest in the kinetic-energy metric. With from_momentum, v1 holds a momentum pt on entry and
    is first mapped to H(q1)^-1 pt, so that pt + J^T eta is the projected momentum.

    Y (m, n), H (n, n), S (m, m) are scratch; eta (m,) receives the momentum impulse.
    Status OK or SINGULAR_MASS (H(q1) or J H^-1 J^T singular)."""
    kern.mass_matrix(q1, t1, p, H)
    if not cholesky_inplace(H):
        return SINGULAR_MASS
    if from_momentum:
        cholesky_solve_inplace(H, v1)
    solve_rows(H, J, Y)
    if not project(J, Y, v1, S, eta, rate):
        return SINGULAR_MASS
    return OK


@njit(inline="always")
def finish_momentum_step(kern, q, v, mom, q1, t1, pt, p, hh, vel, phi, J, gam, Y, H, S, eta, v1,
                         extra, J_next):
    """End of the momentum-form steps (rattle's Newton path, constrained_midpoint), after the
    position stage gave q1 (on Phi = 0) and the momentum pt before the end constraint force:

        p+ = pt + J(q1)^T eta  with  J(q1) H(q1)^-1 p+ = 0,   v+ = H(q1)^-1 p+,   q+ = q1

    then lam = eta / hh (the force at the end of the step, eta = hh mu), the residuals go to
    extra and J(q+) to J_next (m, n), the J(q) of the next step. ``vel`` is the velocity the
    constraints kernel gets at q1 (only its gamma output, unused here, depends on it); gam then
    holds dPhi/dt at (q1, t1), the time of q1. phi, gam,
    eta (m,), J, Y (m, n), H (n, n), S (m, m), v1 (n,) are scratch. Status OK or SINGULAR_MASS;
    on failure q, v, mom are untouched."""
    n, m = q.shape[0], phi.shape[0]
    kern.constraints(q1, vel, t1, p, phi, J, gam)
    constraint_rate(kern, q1, t1, p, gam)
    for i in range(n):
        v1[i] = pt[i]
    subtract_transport(kern, q1, t1, p, v1)   # v = H^-1 (p - b)
    status = velocity_projection(kern, q1, t1, p, J, Y, H, S, eta, v1, True, gam)
    if status != OK:
        return status
    for i in range(n):
        s = pt[i]
        for k in range(m):
            s += J[k, i] * eta[k]
        q[i], v[i], mom[i] = q1[i], v1[i], s
    for k in range(m):
        extra[k] = eta[k] / hh
        for j in range(n):
            J_next[k, j] = J[k, j]
    record(extra, m, phi, J, v, gam)
    return OK
