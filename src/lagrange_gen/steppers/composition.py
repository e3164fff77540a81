"""Yoshida's fourth-order triple jump of Stormer-Verlet.

    Psi_h = V_{g1 h} o V_{g2 h} o V_{g1 h},   g1 = 1 / (2 - 2^(1/3)),   g2 = 1 - 2 g1 < 0

with V the verlet step (velocity Verlet or the generalized leapfrog, see verlet.py). A
composition of symmetric symplectic maps with symmetric coefficients is symmetric and symplectic;
the coefficients cancel the h^3 error term, so the order is 4 (Yoshida, Phys. Lett. A 150, 1990;
Hairer-Lubich-Wanner, GNI, sec. II.4). Cost: three verlet steps per step. The middle substep
runs backwards in time (g2 ~ -1.70); the substeps are longer than h, so on x'' = -omega^2 x the
step is stable (rho = 1) only for tau = h omega < 1.573, against 2 for Verlet.
"""

import sys

from numba import njit

from ..status import OK
from . import verlet
from .spec import PartitionedSettings, Spec
from .base import FAST, W_SAVE_MOM, W_SAVE_Q, W_SAVE_V, copy_into, run_loop

_CBRT2 = 2.0 ** (1.0 / 3.0)
G1 = 1.0 / (2.0 - _CBRT2)
G2 = 1.0 - 2.0 * G1


@njit(**FAST)
def prepare(kern, q, v, mom, t, p, settings, work, mats, piv):
    """The same per-run state as verlet."""
    return verlet.prepare(kern, q, v, mom, t, p, settings, work, mats, piv)


@njit(**FAST)
def step(kern, q, v, mom, t, h, p, settings, work, mats, piv, extra):
    """One step from (q, v, mom) at t, in place. Returns (status, Newton iterations, residual).

    On a failing substep the state is restored to the start of the step."""
    copy_into(work[W_SAVE_Q], q)
    copy_into(work[W_SAVE_V], v)
    copy_into(work[W_SAVE_MOM], mom)
    iters = 0
    resid = 0.0
    t_sub = t
    for k in range(3):
        g = G2 if k == 1 else G1
        status, it, res = verlet.step(kern, q, v, mom, t_sub, g * h, p, settings, work,
                                      mats, piv, extra)
        iters += it
        resid = max(resid, res)
        if status != OK:
            copy_into(q, work[W_SAVE_Q])
            copy_into(v, work[W_SAVE_V])
            copy_into(mom, work[W_SAVE_MOM])
            return status, iters, resid
        t_sub += g * h
    return OK, iters, resid


@njit(inline="always")
def run(kern, q0, v0, t0, h, n_steps, save_every, p, settings,
        out_t, out_q, out_v, out_stats, out_extra, out_last):
    """See base.run_loop."""
    return run_loop(_THIS, kern, q0, v0, t0, h, n_steps, save_every, p, settings,
                    out_t, out_q, out_v, out_stats, out_extra, out_last)


# This module as a value for run_loop (see base.py: modules, not dispatchers, are passed).
_THIS = sys.modules[__name__]

SPEC = Spec(
    name="composition", order=4, family="partitioned", implicit=True, symplectic=True,
    symmetric=True,
    summary="Yoshida 4th-order triple jump of verlet",
    stable="stable for tau < 1.57",
    settings=PartitionedSettings,
    kernels=("energy", "forward_dynamics", "mass_matrix", "mass_matvec_dq", "momentum_rate", "momentum_rate_jacobian"))
