"""Implicit Euler for models with nonsmooth elements: Saint-Venant return map, Moreau-Jean friction.

Smooth part as in ``implicit_euler`` (velocity form, exact Jacobians). With strains s_e(q),
gradients G_e = ds_e/dq and t1 = t + h, one step solves for v+ (q+ = q + h v+):

    H(q+) (v+ - v) - h [rhs(q+, v+, t1) - sum_SV k_e u_e+ G_e(q+)] - h sum_DF r_e G_e(q+) = 0

* Saint-Venant element (stiffness k, threshold eta), internal variable u with
  u' + dpsi_[-eta, eta](u) ∋ s': backward Euler of the inclusion is exactly the return map
  u+ = clamp(u + s(q+) - s(q), -eta, eta). It sits inside a semismooth Newton whose tangent is
  du+/ds+ = 1 while elastic, 0 while sliding (plus the curvature term k u+ d2s/dq2).
* Dry friction (bound F): the force r G with r ∈ -F Sign(G v+) is solved at the velocity level
  (Moreau-Jean): in every Newton iteration the linearized system A dv = -R + h G^T r is reduced
  to the Delassus problem in r (W = h G A^-1 G^T) and solved by projected Gauss-Seidel,
  r_e <- clamp(r_e - (G v)_e / W_ee, -F_e, F_e). No regularization: sticking is exact.

Order 1 (Bastien & Schatzman 2002 for the Prandtl class); for the play operator (prescribed s)
the return map is exact. Newton's tangent is exact for linear strains; for nonlinear strains the
friction gradients are frozen within an iteration (a quasi-Newton that converges linearly).

Element data live in ``extra`` (see ``extra_size``): per element its state (u for Saint-Venant,
the friction force r for dry friction), saved with every output row, then scratch. Row 0 of
out_extra holds the initial states (u0 = 0: virgin material, unless the caller sets them).
With no elements this is exactly ``implicit_euler``.
"""

import sys

from numba import njit

from ..linalg import lu_inplace, lu_solve_inplace
from ..nonsmooth.play import return_map
from ..status import NEWTON_DIVERGED, OK
from .spec import NewtonSettings, Spec
from .base import (FAST, S_MAX_ITER, S_TOL, failed_solve_status, increment_small, max_abs,
                   run_loop)

_V1, _Q1, _DV, _RHS, _R, _S, _X = 0, 1, 2, 3, 4, 5, 6     # work rows (n,)
_H, _A, _JQ, _JQD, _DHW, _HW = 0, 1, 2, 3, 4, 5          # mats (n, n)
_PGS_SWEEPS = 200


def extra_size(n, ne):
    """(saved, total) entries of the ``extra`` buffer: ne saved element states, then scratch."""
    return ne, ne * (8 + 2 * n + ne)


@njit(inline="always")
def _views(extra, n, ne):
    """Views into the flat extra buffer (no allocation of data)."""
    state = extra[0:ne]
    s0 = extra[ne:2 * ne]
    s1 = extra[2 * ne:3 * ne]
    we = extra[3 * ne:4 * ne]
    u1 = extra[4 * ne:5 * ne]
    o = 5 * ne
    G = extra[o:o + ne * n].reshape((ne, n))
    o += ne * n
    coef = extra[o:o + 3 * ne].reshape((ne, 3))
    o += 3 * ne
    Y = extra[o:o + ne * n].reshape((ne, n))       # rows: A^-1 G_e^T (friction elements)
    o += ne * n
    W = extra[o:o + ne * ne].reshape((ne, ne))
    return state, s0, s1, we, u1, G, coef, Y, W


@njit(**FAST)
def prepare(kern, q, v, mom, t, p, settings, work, mats, piv):
    """Nothing is carried in mom; the element state starts at zero (virgin material)."""
    return OK


@njit(inline="always")
def _assemble(kern, q, v, t1, h, p, v1, q1, dv, rhs, R, H, A, Jq, Jqd, dHw, Hw,
              state, s0, s1, we, u1, G, coef):
    """Residual R = -(smooth residual with Saint-Venant forces) and its Jacobian A at v1."""
    n, ne = q.shape[0], state.shape[0]
    for i in range(n):
        q1[i] = q[i] + h * v1[i]
        dv[i] = v1[i] - v[i]
    kern.dynamics(q1, v1, t1, p, H, rhs)
    kern.rhs_jacobian(q1, v1, t1, p, Jq, Jqd)
    kern.mass_matvec_dq(q1, dv, p, dHw)
    kern.elements(q1, p, s1, G, coef)
    for e in range(ne):
        we[e] = 0.0
        if coef[e, 2] == 0.0:                  # Saint-Venant: return map
            k, eta = coef[e, 0], coef[e, 1]
            u1[e] = return_map(state[e], s1[e] - s0[e], eta)
            we[e] = k * u1[e]
            for i in range(n):
                rhs[i] -= k * u1[e] * G[e, i]
    kern.elements_hessian(q1, we, p, Hw)
    for i in range(n):
        s = -h * rhs[i]
        for j in range(n):
            s += H[i, j] * dv[j]
            A[i, j] = H[i, j] + h * dHw[i, j] - h * h * Jq[i, j] - h * Jqd[i, j] + h * h * Hw[i, j]
        R[i] = -s
    for e in range(ne):
        if coef[e, 2] == 0.0:
            trial = state[e] + s1[e] - s0[e]
            if abs(trial) < coef[e, 1]:        # elastic: du+/dv+ = h G_e
                k = coef[e, 0]
                for i in range(n):
                    for j in range(n):
                        A[i, j] += h * h * k * G[e, i] * G[e, j]


@njit(inline="always")
def _delassus(h, A, piv, scratch, G, coef, Y, W):
    """Y_e = A^-1 G_e^T for friction elements (A already LU-factored in place) and the Delassus
    matrix W = h G A^-1 G^T restricted to them (zero elsewhere)."""
    ne, n = G.shape
    for e in range(ne):
        if coef[e, 2] == 1.0:
            for i in range(n):
                Y[e, i] = G[e, i]
            lu_solve_inplace(A, piv, Y[e], scratch)
    for a in range(ne):
        for b in range(ne):
            s = 0.0
            if coef[a, 2] == 1.0 and coef[b, 2] == 1.0:
                for i in range(n):
                    s += G[a, i] * Y[b, i]
            W[a, b] = h * s


@njit(inline="always")
def _pgs(h, tol, v1, X, state, G, coef, Y, W):
    """Projected Gauss-Seidel on r for the velocities v1 + X + h Y^T r. Returns max change."""
    n, ne = X.shape[0], state.shape[0]
    change = 0.0
    for sweep in range(_PGS_SWEEPS):
        change = 0.0
        for e in range(ne):
            if coef[e, 2] != 1.0 or W[e, e] <= 0.0:
                continue
            w = 0.0
            for i in range(n):
                w += G[e, i] * (v1[i] + X[i])
            for b in range(ne):
                w += W[e, b] * state[b] if coef[b, 2] == 1.0 else 0.0
            r_new = min(max(state[e] - w / W[e, e], -coef[e, 0]), coef[e, 0])
            change = max(change, abs(r_new - state[e]))
            state[e] = r_new
        if change <= tol * max(1.0, max_abs(state)):
            break
    return change


@njit(**FAST)
def step(kern, q, v, mom, t, h, p, settings, work, mats, piv, extra):
    """One step from (q, v, element states) at t, in place. Returns (status, iterations, residual)."""
    n, ne = q.shape[0], kern.N_ELEMENTS
    tol, max_iter = settings[S_TOL], int(settings[S_MAX_ITER])
    v1, q1, dv, rhs, R, scratch, X = work[_V1], work[_Q1], work[_DV], work[_RHS], work[_R], work[_S], work[_X]
    H, A, Jq, Jqd, dHw, Hw = mats[_H], mats[_A], mats[_JQ], mats[_JQD], mats[_DHW], mats[_HW]
    state, s0, s1, we, u1, G, coef, Y, W = _views(extra, n, ne)
    kern.elements(q, p, s0, G, coef)
    for i in range(n):
        v1[i] = v[i]
    resid = 0.0
    for it in range(1, max_iter + 1):
        _assemble(kern, q, v, t + h, h, p, v1, q1, dv, rhs, R, H, A, Jq, Jqd, dHw, Hw,
                  state, s0, s1, we, u1, G, coef)
        resid = max_abs(R)
        if resid != resid:
            return NEWTON_DIVERGED, it, resid
        if not lu_inplace(A, piv):
            return failed_solve_status(A), it, resid
        for i in range(n):
            X[i] = R[i]
        lu_solve_inplace(A, piv, X, scratch)
        _delassus(h, A, piv, scratch, G, coef, Y, W)
        _pgs(h, tol, v1, X, state, G, coef, Y, W)
        for e in range(ne):
            if coef[e, 2] == 1.0:
                for i in range(n):
                    X[i] += h * Y[e, i] * state[e]
        for i in range(n):
            v1[i] += X[i]
        if increment_small(X, v1, tol):
            for i in range(n):
                q[i] += h * v1[i]
                v[i] = v1[i]
            kern.elements(q, p, s1, G, coef)
            for e in range(ne):
                if coef[e, 2] == 0.0:
                    state[e] = return_map(state[e], s1[e] - s0[e], coef[e, 1])
            return OK, it, resid
    return NEWTON_DIVERGED, max_iter, resid


@njit(inline="always")
def run(kern, q0, v0, t0, h, n_steps, save_every, p, settings,
        out_t, out_q, out_v, out_stats, out_extra, out_last):
    """See base.run_loop; out_extra (S, extra_size(n, ne)[1]), first ne columns element states."""
    return run_loop(_THIS, kern, q0, v0, t0, h, n_steps, save_every, p, settings,
                    out_t, out_q, out_v, out_stats, out_extra, out_last)


# This module as a value for run_loop (see base.py: modules, not dispatchers, are passed).
_THIS = sys.modules[__name__]

SPEC = Spec(
    name="nonsmooth_euler", order=1, family="nonsmooth", implicit=True, symplectic=False,
    symmetric=False,
    summary="implicit Euler with Saint-Venant return map and Moreau-Jean friction",
    elements=True, stands_in_for=("implicit_euler",), saved=(("element_state", "ne"),),
    settings=NewtonSettings,
    kernels=("dynamics", "elements", "elements_hessian", "energy", "mass_matvec_dq", "rhs_jacobian"))
