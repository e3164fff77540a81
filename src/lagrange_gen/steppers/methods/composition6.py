"""Kahan and Li's sixth-order symmetric composition of Stormer-Verlet, 9 stages (p6 s9).

    Psi_h = V_{g9 h} o ... o V_{g2 h} o V_{g1 h},   g_i = g_{10-i}

with V the verlet step (verlet.py) and the coefficients of Kahan & Li, "Composition constants
for raising the orders of unconventional schemes for ordinary differential equations", Math.
Comp. 66 (1997) 1089-1099, method s9odr6a, as quoted in Hairer-Lubich-Wanner, GNI, sec. V.3.2
(which recommends it over Yoshida's 7-stage solution A for its smaller error constants):

    g1 = g9 =  0.39216144400731413927925056     g4 = g6 = 0.08221359629355080023149045
    g2 = g8 =  0.33259913678935943859974864     g5      = 0.79854399093482996339895035
    g3 = g7 = -0.70624617255763935980996482

Order 6, symmetric and symplectic in (q, p = H(q) v) (a symmetric composition of a symmetric
symplectic method; composition.py). Cost: nine verlet steps per step (nine force evaluations
on verlet's explicit path, nine pairs of Newton solves otherwise).

Linear stability, derived from the step matrix on x'' = -omega^2 x, tau = h omega: the product
of the nine verlet matrices at g_i tau has determinant 1 and |trace / 2| < 1 for
0 < tau < 2.5326 (trace / 2 reaches -1 at tau = 2.532627), so rho = 1 on that interval and
rho > 1 just beyond; it is stable again on an island 2.9191 < tau < 3.3286, not to be relied
on. Per force evaluation that is tau < 0.281, against 0.52 for the triple jump and 2 for
verlet: the method pays off in accuracy (on the cart pendulum over t = 1 at h = 1/32, error
2.3e-9 against 2.2e-5 for the triple jump, for three times its cost), not for stiff motion.
"""

from functools import partial

from ...jit.cache import njit

from .composition import (Workspace, allocate, composed_step, linear_radius,  # noqa: F401
                          palindrome, prepare)
from ..core.options import FAST, inline_step
from ..core.method_spec import PartitionedSettings, Spec

#: (g1, ..., g5, ..., g1), see the module docstring.
COEFFS = palindrome(0.39216144400731413927925056, 0.33259913678935943859974864,
                    -0.70624617255763935980996482, 0.08221359629355080023149045,
                    0.79854399093482996339895035)


@njit
def workspace(kern, n):
    """Allocated once per run by run_loop.run_loop (composition's, for these nine substeps)."""
    return allocate(kern, n, len(COEFFS))


@njit(inline=inline_step, **FAST)
def step(kern, q, v, mom, t, h, p, settings, ws, extra):
    """One step from (q, v, mom) at t, in place. Returns (status, Newton iterations, residual)."""
    return composed_step(kern, q, v, mom, t, h, p, settings, ws, COEFFS)


SPEC = Spec(
    name="composition6", order=6, family="partitioned", implicit=True, symplectic=True,
    symmetric=True,
    summary="Kahan-Li 6th-order 9-stage composition of verlet",
    stable="stable for tau < 2.53", stable_tau=2.5326, rho=partial(linear_radius, COEFFS),
    settings=PartitionedSettings,
    kernels=("forward_dynamics", "mass_matrix", "mass_matvec_dq",
             "momentum_rate", "momentum_rate_jacobian", "transport", "transport_dq"))
