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

Newton uses exact Jacobians: d f/d v from ``momentum_rate_jacobian`` and d(H(q) w)/dq from
``mass_matvec_dq``. Shapes: q, mom, u, w, R, f, scratch (n,); H, A, Jq, Jqd, dHw (n, n).
"""

from numba import njit

from ..status import OK
from . import newton
from .base import FAST


@njit(inline="always")
def assemble_kick(kern, args, u, R, A):
    """Newton system of solve_kick: R = H(q) u + b(q, t) - mom - hk f(q, u, t),
    A = H(q) - hk df/dv."""
    q, mom, t, hk, p, H, Jq, Jqd, f = args
    n = q.shape[0]
    kern.momentum_rate(q, u, t, p, f)
    kern.momentum_rate_jacobian(q, u, t, p, Jq, Jqd)
    for i in range(n):
        s = -mom[i] - hk * f[i]
        for j in range(n):
            s += H[i, j] * u[j]
            A[i, j] = H[i, j] - hk * Jqd[i, j]
        R[i] = s
    if kern.TRANSPORT:
        kern.transport(q, t, p, R)


@njit(**FAST)
def solve_kick(kern, q, mom, t, hk, p, tol, max_iter, H, A, Jq, Jqd, piv, u, R, f, scratch):
    """Solve H(q) u + b(q, t) = mom + hk f(q, u, t) for u (n,); u holds the initial guess on
    entry (b: the T1 = b . v term of T, zero on most models).

    On return H holds H(q) (unfactored) and u the solution.
    Returns (status, iterations, max-norm of the residual at the last iterate).
    """
    kern.mass_matrix(q, t, p, H)
    return newton.solve(_KICK, kern, (q, mom, t, hk, p, H, Jq, Jqd, f), u, R, A, piv,
                        scratch, tol, max_iter)


@njit(inline="always")
def assemble_drift(kern, args, w, R, A):
    """Newton system of solve_drift: R = H(q_new) w + b(q_new, td) - mom, A = H + hd (d(H w)/dq
    + db/dq) at q_new = q + hd (u + w)."""
    q, u, mom, hd, td, p, H, dHw, q_new = args
    n = q.shape[0]
    for i in range(n):
        q_new[i] = q[i] + hd * (u[i] + w[i])
    kern.mass_matrix(q_new, td, p, H)
    kern.mass_matvec_dq(q_new, w, td, p, dHw)
    if kern.TRANSPORT:
        kern.transport_dq(q_new, td, p, dHw)
    for i in range(n):
        s = -mom[i]
        for j in range(n):
            s += H[i, j] * w[j]
            A[i, j] = H[i, j] + hd * dHw[i, j]
        R[i] = s
    if kern.TRANSPORT:
        kern.transport(q_new, td, p, R)


@njit(**FAST)
def solve_drift(kern, q, u, mom, hd, td, p, tol, max_iter, H, A, dHw, piv, w, R, q_new, scratch):
    """Solve H(q_new, td) w + b(q_new, td) = mom with q_new = q + hd (u + w) for w (n,); w holds
    the initial guess on entry (td: the time of the new position).

    On return q_new = q + hd (u + w) and H holds H(q_new) (unfactored).
    Returns (status, iterations, max-norm of the residual at the last iterate).
    """
    status, iters, resid = newton.solve(_DRIFT, kern, (q, u, mom, hd, td, p, H, dHw, q_new),
                                        w, R, A, piv, scratch, tol, max_iter)
    if status == OK:
        for i in range(q.shape[0]):
            q_new[i] = q[i] + hd * (u[i] + w[i])
        kern.mass_matrix(q_new, td, p, H)
    return status, iters, resid


# The two Newton systems as modules for newton.solve (see newton.py: modules, not dispatchers).
_KICK = newton.problem(__name__ + "._kick", assemble_kick)
_DRIFT = newton.problem(__name__ + "._drift", assemble_drift)
