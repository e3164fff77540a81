"""The classical fourth-order Runge-Kutta method on (q, v), the accuracy reference.

    a1 = a(q, v, t)
    a2 = a(q + h/2 v,  v + h/2 a1, t + h/2)           (v2 = v + h/2 a1)
    a3 = a(q + h/2 v2, v + h/2 a2, t + h/2)           (v3 = v + h/2 a2)
    a4 = a(q + h v3,   v + h a3,   t + h)             (v4 = v + h a3)
    q+ = q + h/6 (v + 2 v2 + 2 v3 + v4),   v+ = v + h/6 (a1 + 2 a2 + 2 a3 + a4)

with a = H(q)^-1 (Q - h - g) (generated dynamics, Cholesky), stepped by explicit_rk's
tableau-driven core. Order 4, explicit (four force evaluations), neither symmetric nor
symplectic: energy drifts slowly over long runs. On
x'' = -omega^2 x the stability polynomial is 1 + z + z^2/2 + z^3/6 + z^4/24 at z = i tau,
stable for tau <= 2 sqrt(2).
"""

import math
import sys
from collections import namedtuple

import numpy as np
from ...jit.cache import njit

from ..core.legendre import accel

from ..core.options import FAST, inline_step
from ..core.explicit_rk import RK4_A, RK4_B, RK4_C, rk_step
from ..core.method_spec import ExplicitSettings, Spec
from ..core.status import OK

#: Scratch of one run: stage velocities V_i and accelerations a_i (4, n), the stage position
#: qs (n,), the mass matrix H (n, n) of the forward dynamics.
Workspace = namedtuple("Workspace", "stage_v stage_a qs H")


@njit
def workspace(kern, n):
    """Allocated once per run by run_loop.run_loop."""
    s = RK4_B.shape[0]
    return Workspace(np.zeros((s, n)), np.zeros((s, n)), np.zeros(n), np.zeros((n, n)))


@njit(**FAST)
def prepare(kern, q, v, mom, t, p, settings, ws, extra):
    """Nothing is carried between steps."""
    return OK


@njit(**FAST)
def stage_acceleration(kern, ctx, q, v, t, a):
    """explicit_rk's callback: a (n,) from the generated forward dynamics; ctx = (p, H)."""
    p, H = ctx
    return accel(kern, q, v, t, p, H, a)


@njit(inline=inline_step, **FAST)
def step(kern, q, v, mom, t, h, p, settings, ws, extra):
    """One step from (q, v) at t, in place. Returns (status, 0, 0.0)."""
    status = rk_step(_THIS, kern, (p, ws.H), RK4_A, RK4_B, RK4_C, q, v, t, h,
                     ws.stage_v, ws.stage_a, ws.qs, q, v, False)
    return status, 0, 0.0


# This module as a value for rk_step (see core/run_loop.py: modules, not dispatchers, are passed).
_THIS = sys.modules[__name__]

def linear_radius(tau):
    """|1 + z + z^2/2 + z^3/6 + z^4/24| at z = i tau (x'' = -omega^2 x)."""
    z = 1j * tau
    return abs(1 + z + z**2 / 2 + z**3 / 6 + z**4 / 24)


SPEC = Spec(
    name="rk4", order=4, family="explicit", implicit=False, symplectic=False,
    symmetric=False,
    summary="classical Runge-Kutta 4",
    stable="stable for tau <= 2.83 (2 sqrt(2))",
    stable_tau=2.0 * math.sqrt(2.0), rho=linear_radius,
    settings=ExplicitSettings,
    kernels=("forward_dynamics",))
