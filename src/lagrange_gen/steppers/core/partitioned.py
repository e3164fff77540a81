"""The two implicit half-steps of the partitioned (q, p) schemes, solved by Newton.

For L = 1/2 v^T H(q) v - V(q) with nonconservative forces Q(q, v, t), the Hamiltonian is
K(q, p) = 1/2 p^T H(q)^-1 p + V(q), with dK/dp = v = H(q)^-1 p and dK/dq = -dL/dq(q, v). So the
partitioned steps can be written in velocities, without ever forming H^-1 symbolically, with
f(q, v, t) = dT/dq - dV/dq + Q the generated ``momentum_rate``:

* ``solve_kick``   p+ = p + hk f(q, v+, t),   v+ = H(q)^-1 p+         (implicit in v+)
* ``solve_drift``  q+ = q + hd (u + w),       w  = H(q+)^-1 p         (implicit in w)

With explicit time and a term T1 = b(q, t) . v in T (L = T2 + T1 + T0 - V), p is the canonical
momentum H(q, t) v + b(q, t), v = H^-1 (p - b) and f = dL/dq + Q_nc: the kick's residual gains
b(q, t) and the drift's b(q+, td) with its Jacobian hd db/dq (generated ``transport`` and
``transport_dq``, called only when kern.TRANSPORT).

symplectic_euler is kick(h) followed by q+ = q + h v+; verlet (generalized leapfrog,
Hairer-Lubich-Wanner, Geometric Numerical Integration, sec. VI.3) is kick(h/2), drift(h/2),
explicit kick(h/2). Both unknowns are velocities, which keeps the Newton stopping test
(increment relative to max(1, |unknown|)) meaningful for any h.

Both are solved by simplified Newton (newton.solve_simplified) that starts from the factors
of the mass matrix H(q): the Jacobians of both systems are H plus O(h) terms, so H's factors
contract the iteration by O(h) per step, and H(q) was factored anyway at the end of the
previous step for v = H^-1 p (solve.factor_mass keeps those factors, in LU layout, for the next
kick; the drift starts from what the kick used). Only when that contraction is slower than
newton.THETA_REFRESH (stiff velocity-dependent forces, h far beyond the time scale of the
Coriolis terms) is the exact Jacobian assembled (d f/d v from ``momentum_rate_jacobian``,
d(H(q) w)/dq from ``mass_matvec_dq``) and LU-factored, and kept while it contracts fast.
H's factors and begin_step's extrapolated guess take a few more iterations per step than Newton
with the exact Jacobian, but each iteration is a residual and a triangular solve instead of a
Jacobian and an LU factorization, which on many links is most of the step (verlet up to 32
links: ``lagrange-gen bench scale``, reports/scale.md). Each substep of a composition
extrapolates along its own sequence of earlier solutions, which takes fewer iterations than
starting from v. On small models (n = 2) the step time hardly depends on the iteration count:
an iteration is a small part of the step (``lagrange-gen bench steppers``,
reports/steppers.md).
Shapes: q, mom, u, w, R, f, scratch (n,); H, A, Jq, Jqd, dHw (n, n).
"""

import math

import numpy as np
from ...jit.cache import njit

from . import newton
from .legendre import velocity_from_factors
from .options import FAST
from .solve import factor_mass
from .status import OK, SINGULAR_MASS


@njit(inline="always")
def residual_kick(kern, args, u, R):
    """Residual of solve_kick: R = H(q) u + b(q, t) - mom - hk f(q, u, t)."""
    q, mom, t, hk, p, H, Jq, Jqd, f = args
    n = kern.N_COORDS
    kern.momentum_rate(q, u, t, p, f)
    for i in range(n):
        s = -mom[i] - hk * f[i]
        for j in range(n):
            s += H[i, j] * u[j]
        R[i] = s
    if kern.TRANSPORT:
        kern.transport(q, t, p, R)


@njit(inline="always")
def jacobian_kick(kern, args, u, A):
    """Jacobian of residual_kick: A = H(q) - hk df/dv."""
    q, mom, t, hk, p, H, Jq, Jqd, f = args
    n = kern.N_COORDS
    kern.momentum_rate_jacobian(q, u, t, p, Jq, Jqd)
    for i in range(n):
        for j in range(n):
            A[i, j] = H[i, j] - hk * Jqd[i, j]


# solve_kick and solve_drift are inlined into the step (and with it into the stepping loop), as
# are solve.factor_mass and legendre.velocity_from_factors: as separate functions each call passes
# about a dozen arrays, each as its own pointer, shape and strides, which is a large part of a
# step on small models (ns per step: ``lagrange-gen bench steppers``, reports/steppers.md). The
# price is compile time, most of it numba's inlining pass copying the larger step, which
# lagrange_gen.jit.inline_copy makes cheap (``lagrange-gen bench compile``).
@njit(inline="always")
def solve_kick(kern, q, mom, t, hk, p, tol, max_iter, H, A, Jq, Jqd, piv, u, R, f, scratch,
               contraction_stop):
    """Solve H(q) u + b(q, t) = mom + hk f(q, u, t) for u (n,); u holds the initial guess on
    entry (b: the T1 = b . v term of T, zero on most models). On entry H holds H(q, t) and A,
    piv its factors (solve.factor_mass), the first Newton matrix. contraction_stop: the stopping
    rule (newton.solve_simplified; False in the compositions).

    On return H still holds H(q), A the factors last used, u the solution.
    Returns (status, iterations, max-norm of the residual at the last iterate).
    """
    return newton.solve_simplified(_KICK, kern, (q, mom, t, hk, p, H, Jq, Jqd, f), u, R, A, piv,
                                   scratch, tol, max_iter, True, kern.N_COORDS,
                                   contraction_stop)


@njit(inline="always")
def residual_drift(kern, args, w, R):
    """Residual of solve_drift: R = H(q_new, td) w + b(q_new, td) - mom at q_new = q + hd (u +
    w); leaves q_new and H(q_new) in args."""
    q, u, mom, hd, td, p, H, dHw, q_new = args
    n = kern.N_COORDS
    for i in range(n):
        q_new[i] = q[i] + hd * (u[i] + w[i])
    kern.mass_matrix(q_new, td, p, H)
    for i in range(n):
        s = -mom[i]
        for j in range(n):
            s += H[i, j] * w[j]
        R[i] = s
    if kern.TRANSPORT:
        kern.transport(q_new, td, p, R)


@njit(inline="always")
def jacobian_drift(kern, args, w, A):
    """Jacobian of residual_drift: A = H + hd (d(H w)/dq + db/dq) at the q_new and H(q_new)
    that residual_drift left in args."""
    q, u, mom, hd, td, p, H, dHw, q_new = args
    n = kern.N_COORDS
    kern.mass_matvec_dq(q_new, w, td, p, dHw)
    if kern.TRANSPORT:
        kern.transport_dq(q_new, td, p, dHw)
    for i in range(n):
        for j in range(n):
            A[i, j] = H[i, j] + hd * dHw[i, j]


@njit(inline="always")
def solve_drift(kern, q, u, mom, hd, td, p, tol, max_iter, H, A, dHw, piv, w, R, q_new, scratch,
                contraction_stop):
    """Solve H(q_new, td) w + b(q_new, td) = mom with q_new = q + hd (u + w) for w (n,); w holds
    the initial guess on entry (td: the time of the new position), A and piv the factors the
    kick left (of H(q) or of the kick's Jacobian), the drift's first Newton matrix.
    contraction_stop: as solve_kick's.

    On return q_new = q + hd (u + w) and H holds H (unfactored) at the last iterate the residual
    was evaluated at, q + hd (u + w_prev): it differs from q_new by hd times the last Newton
    increment, within the tolerance (newton.solve_simplified's stopping rule), as everything
    after a Newton solve does. Evaluating H once more at q_new would cost about 6 % of a verlet
    step on the 16-link chain.
    Returns (status, iterations, max-norm of the residual at the last iterate).
    """
    status, iters, resid = newton.solve_simplified(_DRIFT, kern,
                                                   (q, u, mom, hd, td, p, H, dHw, q_new),
                                                   w, R, A, piv, scratch, tol, max_iter, True,
                                                   kern.N_COORDS, contraction_stop)
    if status == OK:
        for i in range(kern.N_COORDS):
            q_new[i] = q[i] + hd * (u[i] + w[i])
    return status, iters, resid


@njit(inline="always")
def begin_step(kern, q, v, t, p, H, A, piv, u, history, carried):
    """Start of a Newton-path step of symplectic_euler or verlet at (q, v, t).

    Makes sure H (n, n) holds H(q, t) and A, piv its factors (solve.factor_mass; carried[0] = 1
    when the previous step left them) and writes the kick's initial guess into u (n,), which
    holds the previous kick's solution u_k on entry (the steps of the sequence have one size).
    u_k goes to the front of history (GUESS_DEGREE + 1, n), the earlier solutions behind it
    (carried[1] counts the solutions kept, u_k included); the guess is their extrapolation of
    degree carried[2] (chosen by best_degree after every kick), or v at degree 0. Both
    carried[0] and carried[1] are cleared until end_step: a failed step leaves nothing to reuse.
    Returns (status, kept): SINGULAR_MASS when H(q) cannot be factored; kept = how many of
    u_k, u_k-1, ... there were (0 on the first step; end_step stores one more)."""
    if carried[0] == 0:
        kern.mass_matrix(q, t, p, H)
        if not factor_mass(H, A, piv, kern.N_COORDS):
            return SINGULAR_MASS, 0
    carried[0] = 0
    kept = carried[1]
    carried[1] = 0
    push(history, u, kern.N_COORDS)
    degree = min(carried[2], kept - 1)
    for i in range(kern.N_COORDS):
        u[i] = extrapolate(history, degree, i) if degree >= 1 else v[i]
    return OK, kept


@njit(inline="always")
def push(history, x, n):
    """Shift the rows of history (GUESS_DEGREE + 1, n) down by one (the last drops out) and put
    x (n,) first; n passed (kern.N_COORDS: options.py, "Loop bounds")."""
    for i in range(n):
        for j in range(GUESS_DEGREE, 0, -1):
            history[j, i] = history[j - 1, i]
        history[0, i] = x[i]


@njit(inline="always")
def extrapolate(history, degree, i):
    """Entry i of the next term of a sequence of equal steps from its latest terms history[0],
    ..., history[degree] (latest first): the polynomial of that degree through them."""
    x = 0.0
    for j in range(degree + 1):
        x += EXTRAPOLATE[degree, j] * history[j, i]
    return x


@njit(inline="always")
def best_degree(history, x, kept, base, n):
    """The degree whose prediction of x (n,) came closest (max norm): 0 for base (n,) (the
    guess without history), d >= 1 for extrapolate(history, d) from the terms before x
    (history (GUESS_DEGREE + 1, n), rows 0..d, kept of them valid; n passed: kern.N_COORDS). A
    sequence that polynomials extrapolate badly (h omega near the stability limit) so falls back
    to a low degree. About GUESS_DEGREE^2 n / 2 multiply-adds, against a residual and a
    triangular solve per Newton iteration saved."""
    best_err = 0.0
    for i in range(n):
        best_err = max(best_err, abs(base[i] - x[i]))
    best = 0
    for d in range(1, min(GUESS_DEGREE, kept - 1) + 1):
        err = 0.0
        for i in range(n):
            err = max(err, abs(extrapolate(history, d, i) - x[i]))
        if err < best_err:
            best, best_err = d, err
    return best


@njit(inline="always")
def end_step(kern, q_new, mom_new, t_new, p, H, A, piv, v_new, scratch, carried, kept,
             depth):
    """End of a Newton-path step: H holds H(q_new, t_new); factor it into A, piv (kept for the
    next step's kick, carried[0] = 1) and solve v_new (n,) = H^-1 (mom_new - b); the solutions
    kept grow by one, up to depth (the rows of the histories). Returns OK or SINGULAR_MASS."""
    if not factor_mass(H, A, piv, kern.N_COORDS):
        return SINGULAR_MASS
    velocity_from_factors(kern, q_new, mom_new, t_new, p, A, piv, v_new, scratch)
    carried[0] = 1
    carried[1] = min(kept + 1, depth)
    return OK


def extrapolation_weights(max_degree):
    """EXTRAPOLATE (max_degree + 1, max_degree + 1): row d holds the weights of x_k, x_k-1, ...,
    x_k-d in the value at step k + 1 of the polynomial of degree d through them (equal steps:
    (-1)^j binomial(d + 1, j + 1); row 0 repeats x_k)."""
    weights = np.zeros((max_degree + 1, max_degree + 1))
    for d in range(max_degree + 1):
        for j in range(d + 1):
            weights[d, j] = (-1.0) ** j * math.comb(d + 1, j + 1)
    return weights


#: Highest degree of the extrapolated Newton guesses (begin_step, verlet's drift). On the
#: 16-link chain (symplectic_euler, h = 1e-3, newton_tol 1e-12) each degree up to 4 saves Newton
#: iterations per step (4.75 at degree 2, 3.27 at 4) and degrees 5 to 7 save none: the guess is
#: then below what one iteration resolves.
GUESS_DEGREE = 4
EXTRAPOLATE = extrapolation_weights(GUESS_DEGREE)

# The two Newton systems as modules for newton.solve_simplified (see newton.py: modules, not dispatchers).
_KICK = newton.problem(__name__ + "._kick", residual=residual_kick, jacobian=jacobian_kick)
_DRIFT = newton.problem(__name__ + "._drift", residual=residual_drift, jacobian=jacobian_drift)
