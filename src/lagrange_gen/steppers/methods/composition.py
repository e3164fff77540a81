"""Symmetric compositions of Stormer-Verlet; this module's method is Yoshida's triple jump.

A composition method with coefficients g_1, ..., g_s (sum 1) is

    Psi_h = V_{g_s h} o ... o V_{g_2 h} o V_{g_1 h}

with V the verlet step (velocity Verlet or the generalized leapfrog, see verlet.py). A
composition of symmetric symplectic maps with symmetric coefficients (g_i = g_{s+1-i}) is
symmetric and symplectic, and its order is even (Hairer-Lubich-Wanner, GNI, sec. II.4 and
V.3). ``composed_step`` is that step for any such coefficients; a composition method is a
module that declares its coefficients (``palindrome``), a ``step`` passing them, and its SPEC
(composition6.py is one). On x'' = -omega^2 x the step matrix is the product of the verlet
matrices at g_i tau, tau = h omega; its determinant is 1, so the step is stable (rho = 1) where
|trace / 2| <= 1 of that product.

This module's method, Yoshida's fourth-order triple jump (Yoshida, Phys. Lett. A 150, 1990;
GNI sec. II.4):

    g1 = g3 = 1 / (2 - 2^(1/3)),   g2 = 1 - 2 g1 ~ -1.70

The coefficients cancel the h^3 error term, so the order is 4. Cost: three verlet steps per step.
The middle substep runs backwards in time; the substeps are longer than h, so on the oscillator
the step is stable only for tau < 1.5734 (|trace / 2| = 1 there), against 2 for Verlet.
"""

from collections import namedtuple
from functools import partial

import numpy as np
from ...jit.cache import njit

from . import verlet
from ..core.options import FAST, explicit_path, inline_step
from ..core.solve import copy_into
from ..core.method_spec import PartitionedSettings, Spec
from ..core.partitioned import GUESS_DEGREE
from ..core.status import OK

#: Scratch of one run: verlet's workspace (its cached acceleration included) and the state at
#: the start of the step, q, v, mom, acc (n,), restored when a substep fails; per substep j
#: (Newton path), guesses (s, 2 GUESS_DEGREE + 3, n): the kick solution, the earlier ones and the
#: earlier drift differences (verlet's u, history, drifts) of substep j, kept (s, 3): how many
#: solutions are kept and the degrees of the next guesses (verlet's carried[1:]): each
#: substep's own sequence has steps of one size, so verlet extrapolates its guesses along it
#: (verlet.step_newton).
Workspace = namedtuple("Workspace", "verlet q v mom acc guesses kept")


def palindrome(*half):
    """The symmetric coefficients (g_1, ..., g_k, ..., g_1) from (g_1, ..., g_k), g_k the middle
    one; checks that they sum to 1 (a consistent composition)."""
    coeffs = tuple(float(g) for g in half + half[-2::-1])
    if abs(sum(coeffs) - 1.0) > 1e-14:
        raise ValueError(f"composition coefficients {coeffs} do not sum to 1")
    return coeffs


def linear_radius(coeffs, tau):
    """rho of the step matrix on x'' = -omega^2 x, tau = h omega: the product of verlet's
    matrices at g tau for g in coeffs."""
    product = np.eye(2)
    for g in coeffs:
        product = verlet.linear_step_matrix(g * tau) @ product
    return float(np.max(np.abs(np.linalg.eigvals(product))))


@njit
def allocate(kern, n, substeps):
    """The workspace of a composition of ``substeps`` verlet steps (n coordinates)."""
    return Workspace(verlet.workspace(kern, n), np.zeros(n), np.zeros(n), np.zeros(n),
                     np.zeros(n), np.zeros((substeps, 2 * GUESS_DEGREE + 3, n)),
                     np.zeros((substeps, 3), np.int64))


@njit
def workspace(kern, n):
    """Allocated once per run by run_loop.run_loop."""
    return allocate(kern, n, len(COEFFS))


@njit(**FAST)
def prepare(kern, q, v, mom, t, p, settings, ws, extra):
    """The per-run state of verlet (its cached acceleration or the momentum); the substeps'
    guesses start over."""
    for j in range(ws.kept.shape[0]):
        ws.kept[j, 0] = ws.kept[j, 1] = ws.kept[j, 2] = 0
    return verlet.prepare(kern, q, v, mom, t, p, settings, ws.verlet, extra)


@njit(inline="always")
def _substep_newton(kern, q, v, mom, t, h, p, settings, ws, j):
    """verlet's Newton-path step as substep j, with the guesses of substep j's own sequence."""
    vw, mine = ws.verlet, ws.guesses[j]
    depth = GUESS_DEGREE + 1            # the rows of verlet's histories
    for i in range(kern.N_COORDS):      # (core/options.py, "Loop bounds")
        vw.u[i] = mine[0, i]
        for k in range(depth):
            vw.history[k, i], vw.drifts[k, i] = mine[1 + k, i], mine[1 + depth + k, i]
    for k in range(1, 4):
        vw.carried[k] = ws.kept[j, k - 1]
    # the increment-alone Newton stop: an error of tol per solve shows in a 4th- or 6th-order
    # result (newton.solve_simplified)
    status, it, res = verlet.step_newton(kern, q, v, mom, t, h, p, settings, vw, False)
    if status == OK:
        for i in range(kern.N_COORDS):
            mine[0, i] = vw.u[i]
            for k in range(depth):
                mine[1 + k, i], mine[1 + depth + k, i] = vw.history[k, i], vw.drifts[k, i]
        for k in range(1, 4):
            ws.kept[j, k - 1] = vw.carried[k]
    return status, it, res


@njit(inline="always")
def composed_step(kern, q, v, mom, t, h, p, settings, ws, coeffs):
    """The verlet substeps g h for g in ``coeffs`` (a tuple of floats) from (q, v, mom) at t, in
    place. Returns (status, Newton iterations summed, largest residual). On a failing substep
    the state (and verlet's cached acceleration) is restored to the start of the step.
    Inlined into each composition's step (one workspace pass less per step, see verlet.py)."""
    copy_into(ws.q, q)
    copy_into(ws.v, v)
    copy_into(ws.mom, mom)
    copy_into(ws.acc, ws.verlet.acc)
    iters = 0
    resid = 0.0
    t_sub = t
    explicit = explicit_path(kern, settings)
    for j in range(len(coeffs)):
        g = coeffs[j]
        # verlet.step's two paths, inlined here (see verlet.py: no workspace passed per substep)
        if explicit:
            status, it, res = verlet.step_explicit(kern, q, v, t_sub, g * h, p, ws.verlet), 0, 0.0
        else:
            status, it, res = _substep_newton(kern, q, v, mom, t_sub, g * h, p, settings, ws, j)
        iters += it
        resid = max(resid, res)
        if status != OK:
            copy_into(q, ws.q)
            copy_into(v, ws.v)
            copy_into(mom, ws.mom)
            copy_into(ws.verlet.acc, ws.acc)
            return status, iters, resid
        t_sub += g * h
    return OK, iters, resid


G1 = 1.0 / (2.0 - 2.0 ** (1.0 / 3.0))
#: Yoshida's triple jump (g1, g2, g1).
COEFFS = palindrome(G1, 1.0 - 2.0 * G1)


@njit(inline=inline_step, **FAST)
def step(kern, q, v, mom, t, h, p, settings, ws, extra):
    """One step from (q, v, mom) at t, in place. Returns (status, Newton iterations, residual)."""
    return composed_step(kern, q, v, mom, t, h, p, settings, ws, COEFFS)


SPEC = Spec(
    name="composition", order=4, family="partitioned", implicit=True, symplectic=True,
    symmetric=True,
    summary="Yoshida 4th-order triple jump of verlet",
    stable="stable for tau < 1.57", stable_tau=1.5734, rho=partial(linear_radius, COEFFS),
    settings=PartitionedSettings,
    kernels=("forward_dynamics", "mass_matrix", "mass_matvec_dq",
             "momentum_rate", "momentum_rate_jacobian", "transport", "transport_dq"))
