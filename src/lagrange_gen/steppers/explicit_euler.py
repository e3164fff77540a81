"""Explicit (forward) Euler: the reference of what not to do.

    q+ = q + h v,   v+ = v + h a(q, v, t),   a = H(q)^-1 (Q - h - g)  (dynamics + Cholesky)

Order 1, neither symmetric nor symplectic. On the linear oscillator x'' = -omega^2 x the step
matrix [[1, h], [-h omega^2, 1]] has eigenvalues 1 +- i tau (tau = h omega), so its spectral
radius is sqrt(1 + tau^2) > 1 for every h: energy grows geometrically, however small h is.
One force evaluation (one Cholesky solve) per step.
"""

import sys

from numba import njit

from ..status import OK
from .spec import ExplicitSettings, Spec
from .base import FAST, accel, run_loop

_A = 0     # work row: acceleration


# No cache=True on functions that receive kernels: they are compiled (and cached) as part of
# the generated module's run_<method> glue, see registry.py.
@njit(**FAST)
def prepare(kern, q, v, mom, t, p, settings, work, mats, piv):
    """Nothing is carried between steps."""
    return OK


@njit(**FAST)
def step(kern, q, v, mom, t, h, p, settings, work, mats, piv, extra):
    """One step from (q, v) at t, in place. Returns (status, 0, 0.0)."""
    a = work[_A]
    status = accel(kern, q, v, t, p, mats[0], a)
    if status != OK:
        return status, 0, 0.0
    for i in range(q.shape[0]):
        q[i] += h * v[i]
        v[i] += h * a[i]
    return OK, 0, 0.0


@njit(inline="always")
def run(kern, q0, v0, t0, h, n_steps, save_every, p, settings,
        out_t, out_q, out_v, out_stats, out_extra, out_last):
    """See base.run_loop."""
    return run_loop(_THIS, kern, q0, v0, t0, h, n_steps, save_every, p, settings,
                    out_t, out_q, out_v, out_stats, out_extra, out_last)


# This module as a value for run_loop (see base.py: modules, not dispatchers, are passed).
_THIS = sys.modules[__name__]

SPEC = Spec(
    name="explicit_euler", order=1, family="explicit", implicit=False, symplectic=False,
    symmetric=False,
    summary="forward Euler (what not to do)",
    stable="unstable for every tau > 0 (rho = sqrt(1 + tau^2))",
    settings=ExplicitSettings,
    kernels=("energy", "forward_dynamics"))
