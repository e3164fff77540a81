"""Explicit (forward) Euler: the reference of what not to do.

    q+ = q + h v,   v+ = v + h a(q, v, t),   a = H(q)^-1 (Q - h - g)  (dynamics + Cholesky)

Order 1, neither symmetric nor symplectic. On the linear oscillator x'' = -omega^2 x the step
matrix [[1, h], [-h omega^2, 1]] has eigenvalues 1 +- i tau (tau = h omega), so its spectral
radius is sqrt(1 + tau^2) > 1 for every h: energy grows geometrically, however small h is.
One force evaluation (one Cholesky solve) per step.
"""

import math
from collections import namedtuple

import numpy as np
from ...jit.cache import njit

from ..core.legendre import accel

from ..core.options import FAST, inline_step
from ..core.method_spec import ExplicitSettings, Spec
from ..core.status import OK

#: Scratch of one run: the acceleration a (n,) and the mass matrix H (n, n) it is solved with.
Workspace = namedtuple("Workspace", "a H")


# No cache=True on functions that receive kernels: they are compiled (and cached) as part of
# the generated module's run_<method> glue, see codegen/glue.py.
@njit
def workspace(kern, n):
    """Allocated once per run by run_loop.run_loop."""
    return Workspace(np.zeros(n), np.zeros((n, n)))


@njit(**FAST)
def prepare(kern, q, v, mom, t, p, settings, ws, extra):
    """Nothing is carried between steps."""
    return OK


@njit(inline=inline_step, **FAST)
def step(kern, q, v, mom, t, h, p, settings, ws, extra):
    """One step from (q, v) at t, in place. Returns (status, 0, 0.0)."""
    a = ws.a
    status = accel(kern, q, v, t, p, ws.H, a)
    if status != OK:
        return status, 0, 0.0
    for i in range(kern.N_COORDS):         # (core/options.py, "Loop bounds")
        q[i] += h * v[i]
        v[i] += h * a[i]
    return OK, 0, 0.0


def linear_radius(tau):
    """rho of the step matrix [[1, tau], [-tau, 1]] on x'' = -omega^2 x: sqrt(1 + tau^2)."""
    return math.sqrt(1.0 + tau * tau)


SPEC = Spec(
    name="explicit_euler", order=1, family="explicit", implicit=False, symplectic=False,
    symmetric=False,
    summary="forward Euler (what not to do)",
    stable="unstable for every tau > 0 (rho = sqrt(1 + tau^2))",
    stable_tau=0.0, rho=linear_radius,
    settings=ExplicitSettings,
    kernels=("forward_dynamics",))
