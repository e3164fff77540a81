"""The Legendre transform and its inverse, mom = H(q, t) v + b(q, t) <-> v, and the forward
dynamics a = H^-1 rhs the explicit methods call (accel).

b(q, t) is the transport term of T1 = b . v (kern.TRANSPORT; b = 0 otherwise). Shapes: q, v,
mom, a (n,); H, A (n, n) workspaces; p (n_params,).
"""

from ...jit.cache import njit

from . import linalg
from .options import FAST
from .solve import copy_into, mass_solve, matvec
from .status import OK, SINGULAR_MASS


@njit(inline="always")
def velocity_from_factors(kern, q, mom, t, p, A, piv, v, scratch):
    """v = H(q, t)^-1 (mom - b(q, t)) (n,) from H's factors in A, piv (factor_mass)."""
    for i in range(kern.N_COORDS):
        v[i] = mom[i]
    subtract_transport(kern, q, t, p, v)
    linalg.lu_solve_inplace(A, piv, v, scratch)


@njit(**FAST)
def accel(kern, q, v, t, p, H, a):
    """a = H(q)^-1 rhs(q, v, t) (n,), H (n, n) workspace; OK or SINGULAR_MASS.

    The generated forward_dynamics (compiled without reference counting) uses the Cholesky factor
    computed at import when H is constant and its parameters have their defaults."""
    return kern.forward_dynamics(q, v, t, p, H, a)


@njit(**FAST)
def velocity_from_momentum(kern, q, mom, t, p, H, v):
    """v = H(q, t)^-1 (mom - b(q, t)) (the inverse Legendre transform; b = 0 unless T has a
    term T1 = b . v, kern.TRANSPORT). Returns OK or SINGULAR_MASS."""
    kern.mass_matrix(q, t, p, H)
    copy_into(v, mom)
    subtract_transport(kern, q, t, p, v)
    return OK if mass_solve(H, v) else SINGULAR_MASS


@njit(**FAST)
def subtract_transport(kern, q, t, p, x):
    """x (n,) <- x - b(q, t) on a model with T1 = b . v (kern.TRANSPORT; nothing otherwise). The
    generated ``transport`` adds b, so x is negated around it."""
    if kern.TRANSPORT:
        for i in range(x.shape[0]):
            x[i] = -x[i]
        kern.transport(q, t, p, x)
        for i in range(x.shape[0]):
            x[i] = -x[i]


@njit(**FAST)
def momentum_from_velocity(kern, q, v, t, p, H, mom):
    """mom = H(q, t) v + b(q, t) (the Legendre transform, canonical momentum dL/dv)."""
    kern.mass_matrix(q, t, p, H)
    matvec(H, v, mom, kern.N_COORDS)
    if kern.TRANSPORT:
        kern.transport(q, t, p, mom)
