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

Both are solved by simplified Newton (newton.solve_simplified): the exact Jacobian (d f/d v
from ``momentum_rate_jacobian``, d(H(q) w)/dq from ``mass_matvec_dq``) is assembled and
factored at the first iterate and reused while the iteration contracts by at least 4 per
iteration; later iterations evaluate the residual alone. Both Jacobians are H plus O(h) terms
that change little within a step, so the iteration counts equal Newton's (measured: 3.0 and
5.6 per step on the 16-link chain, 2 and 4 on the cart pendulum) while a step does one
Jacobian and one LU factorization per system instead of one per iteration: 16-link chain
symplectic_euler 12.5 -> 7.0 us, verlet 19.5 -> 11.4 us per step; the cart pendulum unchanged
within noise (226 -> 227 ns symplectic_euler). Shapes: q, mom, u, w, R, f, scratch (n,); H, A, Jq, Jqd, dHw (n, n).
"""

from numba import njit

from ..status import OK
from . import newton
from .base import FAST


@njit(inline="always")
def residual_kick(kern, args, u, R):
    """Residual of solve_kick: R = H(q) u + b(q, t) - mom - hk f(q, u, t)."""
    q, mom, t, hk, p, H, Jq, Jqd, f = args
    n = q.shape[0]
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
    n = q.shape[0]
    kern.momentum_rate_jacobian(q, u, t, p, Jq, Jqd)
    for i in range(n):
        for j in range(n):
            A[i, j] = H[i, j] - hk * Jqd[i, j]


@njit(**FAST)
def solve_kick(kern, q, mom, t, hk, p, tol, max_iter, H, A, Jq, Jqd, piv, u, R, f, scratch):
    """Solve H(q) u + b(q, t) = mom + hk f(q, u, t) for u (n,); u holds the initial guess on
    entry (b: the T1 = b . v term of T, zero on most models).

    On return H holds H(q) (unfactored) and u the solution.
    Returns (status, iterations, max-norm of the residual at the last iterate).
    """
    kern.mass_matrix(q, t, p, H)
    return newton.solve_simplified(_KICK, kern, (q, mom, t, hk, p, H, Jq, Jqd, f), u, R, A, piv,
                                   scratch, tol, max_iter)


@njit(inline="always")
def residual_drift(kern, args, w, R):
    """Residual of solve_drift: R = H(q_new, td) w + b(q_new, td) - mom at q_new = q + hd (u +
    w); leaves q_new and H(q_new) in args."""
    q, u, mom, hd, td, p, H, dHw, q_new = args
    n = q.shape[0]
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
    n = q.shape[0]
    kern.mass_matvec_dq(q_new, w, td, p, dHw)
    if kern.TRANSPORT:
        kern.transport_dq(q_new, td, p, dHw)
    for i in range(n):
        for j in range(n):
            A[i, j] = H[i, j] + hd * dHw[i, j]


@njit(**FAST)
def solve_drift(kern, q, u, mom, hd, td, p, tol, max_iter, H, A, dHw, piv, w, R, q_new, scratch):
    """Solve H(q_new, td) w + b(q_new, td) = mom with q_new = q + hd (u + w) for w (n,); w holds
    the initial guess on entry (td: the time of the new position).

    On return q_new = q + hd (u + w) and H holds H(q_new) (unfactored).
    Returns (status, iterations, max-norm of the residual at the last iterate).
    """
    status, iters, resid = newton.solve_simplified(_DRIFT, kern,
                                                   (q, u, mom, hd, td, p, H, dHw, q_new),
                                                   w, R, A, piv, scratch, tol, max_iter)
    if status == OK:
        for i in range(q.shape[0]):
            q_new[i] = q[i] + hd * (u[i] + w[i])
        kern.mass_matrix(q_new, td, p, H)
    return status, iters, resid


# The two Newton systems as modules for newton.solve_simplified (see newton.py: modules, not dispatchers).
_KICK = newton.problem(__name__ + "._kick", residual=residual_kick, jacobian=jacobian_kick)
_DRIFT = newton.problem(__name__ + "._drift", residual=residual_drift, jacobian=jacobian_drift)
