"""The two implicit half-steps of the partitioned (q, p) schemes, solved by Newton.

For L = 1/2 v^T H(q) v - V(q) with nonconservative forces Q(q, v, t), the Hamiltonian is
K(q, p) = 1/2 p^T H(q)^-1 p + V(q), with dK/dp = v = H(q)^-1 p and dK/dq = -dL/dq(q, v). So the
partitioned steps can be written in velocities, without ever forming H^-1 symbolically, with
f(q, v, t) = dT/dq - dV/dq + Q the generated ``momentum_rate``:

* ``solve_kick``   p+ = p + hk f(q, v+, t),   v+ = H(q)^-1 p+         (implicit in v+)
* ``solve_drift``  q+ = q + hd (u + w),       w  = H(q+)^-1 p         (implicit in w)

symplectic_euler is kick(h) followed by q+ = q + h v+; verlet (generalized leapfrog,
Hairer-Lubich-Wanner, Geometric Numerical Integration, sec. VI.3) is kick(h/2), drift(h/2),
explicit kick(h/2). Both unknowns are velocities, which keeps the Newton stopping test
(increment relative to max(1, |unknown|)) meaningful for any h.

Newton uses exact Jacobians: d f/d v from ``momentum_rate_jacobian`` and d(H(q) w)/dq from
``mass_matvec_dq``. Shapes: q, mom, u, w, R, f, scratch (n,); H, A, Jq, Jqd, dHw (n, n).
"""

from numba import njit

from ..status import NEWTON_DIVERGED, OK
from .base import FAST, max_abs, newton_converged, newton_solve


@njit(**FAST)
def solve_kick(kern, q, mom, t, hk, p, tol, max_iter, H, A, Jq, Jqd, piv, u, R, f, scratch):
    """Solve H(q) u = mom + hk f(q, u, t) for u (n,); u holds the initial guess on entry.

    On return H holds H(q) (unfactored) and u the solution.
    Returns (status, iterations, max-norm of the residual at the last iterate).
    """
    n = q.shape[0]
    kern.mass_matrix(q, p, H)
    resid = prev = 0.0
    for it in range(1, max_iter + 1):
        kern.momentum_rate(q, u, t, p, f)
        kern.momentum_rate_jacobian(q, u, t, p, Jq, Jqd)
        for i in range(n):
            s = -mom[i] - hk * f[i]
            for j in range(n):
                s += H[i, j] * u[j]
                A[i, j] = H[i, j] - hk * Jqd[i, j]
            R[i] = -s
        resid = max_abs(R)
        if resid != resid:
            return NEWTON_DIVERGED, it, resid
        status = newton_solve(A, piv, R, scratch)
        if status != OK:
            return status, it, resid
        for i in range(n):
            u[i] += R[i]
        done, prev = newton_converged(R, u, prev, tol)
        if done:
            return OK, it, resid
    return NEWTON_DIVERGED, max_iter, resid


@njit(**FAST)
def solve_drift(kern, q, u, mom, hd, p, tol, max_iter, H, A, dHw, piv, w, R, q_new, scratch):
    """Solve H(q + hd (u + w)) w = mom for w (n,); w holds the initial guess on entry.

    On return q_new = q + hd (u + w) and H holds H(q_new) (unfactored).
    Returns (status, iterations, max-norm of the residual at the last iterate).
    """
    n = q.shape[0]
    resid = prev = 0.0
    for it in range(1, max_iter + 1):
        for i in range(n):
            q_new[i] = q[i] + hd * (u[i] + w[i])
        kern.mass_matrix(q_new, p, H)
        kern.mass_matvec_dq(q_new, w, p, dHw)
        # R(w) = H(q_new(w)) w - mom;  dR/dw = H + hd d(H w)/dq
        for i in range(n):
            s = -mom[i]
            for j in range(n):
                s += H[i, j] * w[j]
                A[i, j] = H[i, j] + hd * dHw[i, j]
            R[i] = -s
        resid = max_abs(R)
        if resid != resid:
            return NEWTON_DIVERGED, it, resid
        status = newton_solve(A, piv, R, scratch)
        if status != OK:
            return status, it, resid
        for i in range(n):
            w[i] += R[i]
        done, prev = newton_converged(R, w, prev, tol)
        if done:
            for i in range(n):
                q_new[i] = q[i] + hd * (u[i] + w[i])
            kern.mass_matrix(q_new, p, H)
            return OK, it, resid
    return NEWTON_DIVERGED, max_iter, resid
