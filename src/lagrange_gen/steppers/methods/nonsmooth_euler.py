"""Implicit Euler for models with nonsmooth elements: Saint-Venant return map, Moreau-Jean friction.

Smooth part as in ``implicit_euler`` (velocity form, exact Jacobians). With strains s_e(q),
gradients G_e = ds_e/dq and t1 = t + h, one step solves for v+ (q+ = q + h v+):

    R(v+) = H(q+) (v+ - v) - h [rhs(q+, v+, t1) - sum_SV k_e u_e+ G_e(q+)] - h sum_DF r_e G_e(q+) = 0

* Saint-Venant element (stiffness k, threshold eta), internal variable u with
  u' + dpsi_[-eta, eta](u) ∋ s': backward Euler of the inclusion is exactly the return map
  u+ = clamp(u + s(q+) - s(q), -eta, eta). It sits inside a semismooth Newton whose tangent is
  du+/ds+ = 1 while elastic, 0 while sliding (plus the curvature term k u+ d2s/dq2).
* Dry friction (bound F): the force r G with r ∈ -F Sign(G v+) is solved at the velocity level
  (Moreau-Jean): in every Newton iteration the linearized system A dv = -R_s + h G^T r (R_s the
  residual without friction) is reduced to the Delassus problem in r (W = h G A^-1 G^T) and
  solved by projected Gauss-Seidel, r_e <- clamp(r_e - (G v)_e / W_ee, -F_e, F_e). No
  regularization: sticking is exact.

One Newton loop (newton.solve; its stopping rule, iteration cap and status codes), with the
nonsmooth work in the assembly. At the iterate v1 it evaluates the return map (u+ from the trial
strain; the Saint-Venant states are updated only once the step is accepted) and assembles
F = R_s(v1), A = dR_s/dv1 (exact for linear strains). Without friction elements that is the
system newton.solve solves. With friction elements the increment needs A^-1 before the forces
are known (the Delassus problem), so the assembly factors A itself, solves the
Delassus problem (updating r in the element states) and hands newton.solve the Newton system
premultiplied by that A^-1: F <- -dv = -(X + h A^-1 G^T r) with X = -A^-1 R_s, whose Jacobian at
the iterate is the identity (A <- I). newton.solve's update x -= I^-1 F is then the Moreau-Jean
increment, in the same floating-point operations as the increment the projected Gauss-Seidel
zeroes (G (v1 + dv) = 0): a sticking block stays at exactly v = 0, with no creep. The residual
reported for friction models is therefore max|dv| of the last iteration.

Order 1 (Bastien & Schatzman 2002 for the Prandtl class); for the play operator (prescribed s)
the return map is exact. Newton's tangent is exact for linear strains; for nonlinear strains the
friction gradients are frozen within an iteration (a quasi-Newton that converges linearly).

``extra`` (ne,) holds the element states, saved with every output row (u for Saint-Venant, the
friction force r for dry friction); row 0 of out_extra holds the initial states (u0 = 0: virgin
material, unless the caller sets them). With no elements this is exactly ``implicit_euler``.
"""

import sys
from collections import namedtuple

import numpy as np
from ...jit.cache import njit

from ..core import newton
from ..core.options import FAST, inline_step
from ..core.solve import failed_solve_status, max_abs
from ..core.linalg import lu_inplace, lu_solve_inplace
from ..core.method_spec import NewtonSettings, Spec
from ..core.status import OK, SINGULAR_NEWTON
from ...nonsmooth.play import return_map

_PGS_SWEEPS = 200

#: Scratch of one run. (n,): the Newton unknown v1 = v+, q1 = q+, dv = v+ - v, rhs, residual F,
#: solver scratch s and pivots piv, the friction-free increment X; (n, n): H, the Newton matrix
#: A (factored in place for the Delassus problem when there is friction), d rhs/dq, d rhs/dv,
#: d(H w)/dq, the element Hessian term Hw; (ne,): strains s0 at q and s1 at q1, Saint-Venant
#: weights we = k u+ and trial states u1; G (ne, n) strain gradients, coef (ne, 3) the
#: elements' (k or F, eta, kind), Y (ne, n) rows A^-1 G_e^T, W (ne, ne) the Delassus matrix.
Workspace = namedtuple("Workspace", "v1 q1 dv rhs F s X piv H A Jq Jqd dHw Hw "
                                    "s0 s1 we u1 G coef Y W")


@njit
def workspace(kern, n):
    """Allocated once per run by run_loop.run_loop."""
    ne = kern.N_ELEMENTS
    return Workspace(np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n),
                     np.zeros(n), np.zeros(n), np.zeros(n, np.int64), np.zeros((n, n)),
                     np.zeros((n, n)), np.zeros((n, n)), np.zeros((n, n)), np.zeros((n, n)),
                     np.zeros((n, n)),
                     np.zeros(ne), np.zeros(ne), np.zeros(ne), np.zeros(ne),
                     np.zeros((ne, n)), np.zeros((ne, 3)), np.zeros((ne, n)), np.zeros((ne, ne)))


@njit(**FAST)
def prepare(kern, q, v, mom, t, p, settings, ws, extra):
    """Nothing is carried in mom; the element states come in extra (row 0 of out_extra)."""
    return OK


@njit(inline="always")
def _smooth_and_sliders(kern, q, v, t1, h, p, v1, q1, dv, rhs, F, H, A, Jq, Jqd, dHw, Hw,
                        state, s0, s1, we, u1, G, coef):
    """F (n,) <- R_s(v1), the residual with the Saint-Venant forces from the return map, and
    A (n, n) <- dR_s/dv1 (semismooth: the elastic elements' stiffness, none while sliding)."""
    n, ne = q.shape[0], state.shape[0]
    for i in range(n):
        q1[i] = q[i] + h * v1[i]
        dv[i] = v1[i] - v[i]
    kern.dynamics(q1, v1, t1, p, H, rhs)
    kern.rhs_jacobian(q1, v1, t1, p, Jq, Jqd)
    kern.mass_matvec_dq(q1, dv, t1, p, dHw)
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
        F[i] = s
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
def _pgs(tol, v1, X, state, G, coef, W):
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


@njit(inline="always")
def _friction(h, tol, v1, F, A, piv, X, scratch, state, G, coef, Y, W):
    """With friction elements: the Moreau-Jean increment dv = X + h Y^T r (X = -A^-1 F, the
    forces r from projected Gauss-Seidel, updated in state), handed to newton.solve as
    F <- -dv, A <- I (see the module docstring); A is factored in place on the way. Without
    friction elements F and A are left alone. If A cannot be factored it is replaced by a
    matrix newton.solve fails on with the same status (zeros: SINGULAR_NEWTON, NaN:
    NON_FINITE)."""
    ne, n = G.shape
    friction = False
    for e in range(ne):
        friction = friction or coef[e, 2] == 1.0
    if not friction:
        return
    if not lu_inplace(A, piv):
        fill = 0.0 if failed_solve_status(A) == SINGULAR_NEWTON else np.nan
        for i in range(n):
            for j in range(n):
                A[i, j] = fill
        return
    for i in range(n):
        X[i] = -F[i]
    lu_solve_inplace(A, piv, X, scratch)
    _delassus(h, A, piv, scratch, G, coef, Y, W)
    _pgs(tol, v1, X, state, G, coef, W)
    for e in range(ne):
        if coef[e, 2] == 1.0:
            for i in range(n):
                X[i] += h * Y[e, i] * state[e]
    for i in range(n):
        F[i] = -X[i]
        for j in range(n):
            A[i, j] = 1.0 if i == j else 0.0


@njit(inline="always")
def assemble(kern, args, v1, F, A):
    """Newton system of the step (newton.solve) at the iterate v1: F (n,) <- R_s(v1) and
    A (n, n) <- dR_s/dv1, or with friction elements the increment form F <- -dv, A <- I."""
    (q, v, t1, h, p, tol, q1, dv, rhs, H, Jq, Jqd, dHw, Hw, piv, X, scratch,
     state, s0, s1, we, u1, G, coef, Y, W) = args
    _smooth_and_sliders(kern, q, v, t1, h, p, v1, q1, dv, rhs, F, H, A, Jq, Jqd, dHw, Hw,
                        state, s0, s1, we, u1, G, coef)
    _friction(h, tol, v1, F, A, piv, X, scratch, state, G, coef, Y, W)


@njit(inline=inline_step, **FAST)
def step(kern, q, v, mom, t, h, p, settings, ws, extra):
    """One step from (q, v, element states extra (ne,)) at t, in place. Returns (status,
    iterations, residual)."""
    n = q.shape[0]
    state, s0, s1, G, coef = extra, ws.s0, ws.s1, ws.G, ws.coef
    kern.elements(q, p, s0, G, coef)
    v1 = ws.v1
    for i in range(n):
        v1[i] = v[i]
    args = (q, v, t + h, h, p, settings.newton_tol, ws.q1, ws.dv, ws.rhs, ws.H, ws.Jq, ws.Jqd,
            ws.dHw, ws.Hw, ws.piv, ws.X, ws.s, state, s0, s1, ws.we, ws.u1, G, coef,
            ws.Y, ws.W)
    status, iters, resid = newton.solve(_THIS, kern, args, v1, ws.F, ws.A, ws.piv, ws.s,
                                        settings.newton_tol, settings.max_iter, v1.shape[0])
    if status != OK:
        return status, iters, resid
    for i in range(n):
        q[i] += h * v1[i]
        v[i] = v1[i]
    kern.elements(q, p, s1, G, coef)
    for e in range(state.shape[0]):
        if coef[e, 2] == 0.0:
            state[e] = return_map(state[e], s1[e] - s0[e], coef[e, 1])
    return OK, iters, resid


# This module as a value for newton.solve (see core/run_loop.py: modules, not dispatchers, are passed).
_THIS = sys.modules[__name__]

SPEC = Spec(
    name="nonsmooth_euler", order=1, family="nonsmooth", implicit=True, symplectic=False,
    symmetric=False,
    summary="implicit Euler with Saint-Venant return map and Moreau-Jean friction",
    elements=True, stands_in_for=("implicit_euler",), saved=(("element_state", "ne"),),
    settings=NewtonSettings,
    kernels=("dynamics", "elements", "elements_hessian", "mass_matvec_dq", "rhs_jacobian"))
