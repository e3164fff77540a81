"""Event-driven stepping of unilateral contacts: dop853 between switches, Newton's impact law at
located impacts, persistent contacts held at the acceleration level, a Zeno guard.

Each contact a is in one mode: FREE (its gap g_a(q, t) > 0 may close) or persistent (g_a = 0
held, the contact force lambda_N >= 0 watched), and a persistent one with friction STICKs
(u_T = 0, |lambda_T| <= mu lambda_N) or slides: with one tangent SLIDE_POSITIVE /
SLIDE_NEGATIVE (lambda_T = -mu lambda_N sign(u_T)); with two (the 3D cone) SLIDE, the force
lambda_T = -mu lambda_N d along the current slip direction d = u_T / |u_T| of the pair
(u_T1, u_T2), recomputed at every stage from the velocities (the path may curve). The local
velocities are u = W v + b(q, t) (b: generated ``contact_bias``, a moving surface's velocity).
Between switches the motion is smooth: dop853's tableau, error control and dense output
(dop853.attempt_on, accept_on, dense_on) on the acceleration

    M a = f + W^T lambda,   W a + rate = 0 on the persistent rows (normal; tangent if sticking)

with lambda from the contact problem at the acceleration level (core/contact_problem.py:
BILATERAL normals, STICK or SLIDE tangents; rate the generated ``contact_rates``, dW/dt v and a
moving surface's time derivatives).

Switches are zero crossings, located on the dense output by events.refine (Illinois), of one
function per contact and direction (all falling through 0): FREE: the gap g_a; persistent:
lambda_N (lift-off); STICK: mu lambda_N - |lambda_T| (slip starts; |.| the pair's length in
3D); SLIDE_*: s u_T (the slip velocity reverses; s its sign); SLIDE: s_ref . u_T with s_ref the
slip direction at the step's start (|u_T| falls to zero where the slip stops; past it the
force keeps the sign s_ref . u_T gives it, d = sign(s_ref . u_T) u_T / |u_T|, so that the
motion stays smooth through the crossing and the root is a plain sign change). The step ends at
the earliest one (adaptive.run_adaptive's switch_point / apply_switch hooks); the run goes on
from there after ``classify``:

1. Impact: the contacts touching (g <= gap_tol) and not separating (u_N <= rest_velocity,
   u_N = W_N v + dg/dt the velocity relative to the surface) take part; if one approaches
   (u_N < -rest_velocity), Newton's impact law with Coulomb friction (interval or disk) at the
   velocity level, u_N+ + e min(u_N-, 0) >= 0 _|_ p_N >= 0 (several
   simultaneous contacts: one problem, the same projected Gauss-Seidel as moreau_jean, with
   Lemke's method behind it, core/contact_lcp.py, for every contact problem here), and
   v+ = v- + M^-1 W^T p.
   Zeno guard: a contact whose previous impact was less than zeno_interval ago gets e = 0 in
   this impact (an accumulation of impacts, t_k -> t_inf, ends there in a plastic one).
2. Modes: a touching contact with |u_N| <= rest_velocity is persistent if its force at the
   acceleration level is positive (else FREE); with friction it sticks if |u_T| <= rest_velocity
   and the sticking force fits the cone (else it slides, away from the sticking force; a
   moving one slides along u_T). The
   velocities are then projected onto the persistent rows (u_N = 0; u_T = 0 when sticking) by
   the same solver, so that rest stays rest.

Holonomic constraints Phi(q, t) = 0 (m rows, J = dPhi/dq; N = n + m): the motion between
switches is the index-1 form

    K (a, lam) = (f + W^T lambda, gamma),   K = [[M, -J^T], [J, 0]]   (gamma = -dJ/dt v, the
                                                                      generated ``constraints``)

from one LU of K per evaluation (M a = f + J^T lam + W^T lambda, J a = gamma); the contact
problems (the persistent contacts' forces, the impact, the rest projection) take K as their
factored matrix with W padded by m zero columns (core/contact_kkt.pad_rows, the same
contact_problem.delassus), so the constraint forces and impulses follow the contact ones exactly
and an impulse keeps J v = 0. No Baumgarte term: Phi'' = 0 holds to the integration error, so
Phi drifts by that between switches; each switch (and the start) first projects q onto
Phi(q, t) = 0 (the nearest point in the metric of M: newton.solve on assemble_projection) and v
onto J v + dPhi/dt = 0 (one solve with K). Without constraints K is M and N = n.

Orders: 8 between switches; the switch times are roots of the dense output (order 7), to
events.ROOT_RTOL of the step. The gap of a persistent contact is held at the acceleration
level, so it drifts by the integration error (rtol, atol).

Reported (SPEC.saved, c = kern.N_CONTACTS), cumulative since t0 except the modes: ``impacts``
(1) the impacts so far, ``normal_impulse_sum``, ``tangent_impulse_sum`` (c) the impulses of
the impacts and projections summed per contact (``tangent2_impulse_sum`` (c) the second
tangent's), ``contact_mode`` (c) FREE 0, STICK 1, SLIDE_POSITIVE 2, SLIDE_NEGATIVE 3, SLIDE 4,
``contact_work`` (1) the work of the impulses, r . (W v- + W v+) / 2, plus that of the
persistent contacts' forces, their power lambda . (W v) integrated like W (dop853.py): its
values at the stages, the tableau's sum over a step and the dense output's integral over a step
that ends at a switch (orders 8 and 7: a curving 3D slide or a moving surface to the method's
accuracy). E - E0 - contact_work is then the balance for conservative forces; forces that do
work (kern.WORK) add W, which dop853's functions step with the state (W' = P at the stages, see
dop853.py) and which a switch leaves as it is: E - E0 - W - contact_work. Row 0
is the state after the start's classification (an impact at t0 is in the impulse sums); the
work counts from it. In every-step mode a switch writes two rows at its time: before and after (diff the sums for an
impact's impulses).

With holonomic constraints, after ``last_impact``: ``multipliers`` (m) lam at the row's state
(the persistent contacts' forces included), ``constraint_error`` max|Phi| and
``velocity_constraint_error`` max|J v + dPhi/dt| (1 each; core/constrained.SAVED's fields).

``last_impact`` (c) is each contact's latest impact time (-inf before its first): the Zeno
guard's memory. A run continued in chunks (run/adaptive_driver.py) reclassifies the contacts
at each chunk's start and takes that memory back from the saved fields, so the guard acts the
same whatever the chunk boundaries.

Over 300 lines: the switching functions, the classification at a switch (impact, modes,
projection) and the work accounting read and write one workspace and one ``extra`` layout, so
they stay beside each other and the docstring that defines them.
"""

import sys
from collections import namedtuple
from typing import NamedTuple

import numpy as np
from ...jit.cache import njit

from ..core import events, newton
from ..core.constrained import constraint_rate
from ..core.contact_problem import (BILATERAL, SLIDE, SLIDE_NEGATIVE, SLIDE_POSITIVE, STICK,
                                    contact_row, delassus)
from ..core.contact_kkt import assemble_constraint_rows, pad_rows, record_constraints
from ..core.contact_lcp import contact_solve, lcp_arrays
from ..core.linalg import lu_inplace, lu_solve_inplace
from ..core.method_spec import Spec
from ..core.options import FAST
from ..core.status import OK, SINGULAR_MASS
from . import dop853

#: Contact modes (saved as contact_mode); STICK, SLIDE_* as the tangent laws.
FREE = 0

ERROR_EXPONENT = dop853.ERROR_EXPONENT
STAGE_EVALS = dop853.STAGE_EVALS
ACCEPT_EVALS = dop853.ACCEPT_EVALS
DENSE_EVALS = dop853.DENSE_EVALS
#: A switch writes the state before it and the state after it (every-step mode).
ROWS_PER_STEP = 2

#: Saved-field offsets in ``extra`` (c contacts): impacts, normal sums, tangent 1 and tangent 2
#: sums, modes, work.
IMPACTS = 0

#: The projection of q onto Phi(q, t) = 0 at a switch (Newton, newton.solve): its stopping
#: tolerance (relative to max(1, |q|)) and iteration cap. It starts within the integration
#: error of the manifold (rtol, atol), so two iterations are the usual count.
PROJECTION_TOL = 1e-14
PROJECTION_MAX_ITER = 20


class Settings(NamedTuple):
    """Settings of dop853_impacts (simulate's keywords)."""

    rtol: float = 1e-9              # relative tolerance of the local error estimate
    atol: float = 1e-12             # absolute tolerance (same units as q and v)
    h_max: float = np.inf           # largest step size
    max_steps: int = 100000         # cap on attempted (accepted + rejected) steps per call
    blowup_bound: float = 1e150     # UNSTABLE when max(|q|, |v|) exceeds it
    zeno_interval: float = 1e-5     # impacts of a contact closer than this: the next is plastic
    gap_tol: float = 1e-9           # a contact touches when its gap is at most this
    rest_velocity: float = 1e-9     # |u_N| (|u_T|) at most this: at rest (sticking)
    contact_tol: float = 1e-12      # projected Gauss-Seidel stop: max change <= tol * max|r|
    max_sweeps: int = 1000          # cap on the Gauss-Seidel sweeps of one contact problem


#: dop853's fields (its functions read them by name, the work's included), then, c contacts: M (n, n) the mass
#: matrix (LU-factored), f (n,) rhs, s (n,) scratch, piv (n,) pivots, acc (n,) scratch
#: acceleration; g (c,), WN (c, n), WT (2c, n), coef (c, 2) = (e, mu), rate (3c,) (contact_rates),
#: bias (3c,) (contact_bias); r (3c,) forces or impulses, uf (3c,) free local
#: velocities/accelerations, zero (c,) zeros, un (c,)
#: normal velocities before an impact; mode (c,) int; law (2c,) int (acceleration level),
#: impact_law (2c,) zeros (UNILATERAL / COULOMB); persistent (c,) and touching (c,) 0/1 flags;
#: coef_impact (c, 2); last_impact (c,) times; Y (3c, n), D (3c, 3c) (contact_problem);
#: switch values at the step's start and end and at trial times sw_prev, sw_new (2c,) with
#: the events workspace sw (refine's); power (2,) = [at the last evaluation, at the step's
#: start]; contact_stages (16, 1) that power at the stages of the step, stage_at (1,) the
#: stage the next stage_acceleration evaluates, quad_F (7, 1), quad_ends (2,) scratch of its
#: dense integral; solver (4,) = (contact_tol, max_sweeps, gap_tol) for the stage accelerations
#: and switching functions, and 1 while the start state is not classified yet; left_at (c,) the
#: time a free contact was last touching (-inf: not since the step it cleared gap_tol);
#: bias (3c,) (contact_bias); slide_ref (2c,) the slip direction of a SLIDE contact at the
#: step's start (pairs (slide_ref[a], slide_ref[c + a])), slide (2c,) the force's direction at
#: the last evaluation; lcp_B, lcp_C, lcp_T, lcp_z, lcp_basis the exact fallback's scratch
#: (core/contact_lcp.lcp_arrays).
#: With m holonomic constraints (N = n + m; N = n and the constraint arrays empty without): K
#: (N, N) the KKT matrix [[M, -J^T], [J, 0]] (LU-factored; s, piv (N,) its scratch and pivots,
#: Y (3c, N) the rows K^-1 [W_k^T; 0]), x (N,) the KKT unknown (acceleration or velocity
#: change, then the constraint multipliers or impulses), F, xq (N,) the position projection's
#: residual and unknown (q, mu); phi, gam (m,) Phi and gamma (J qdd = gamma along a motion),
#: crate (m,) dPhi/dt, G (m, n) J; WNp (c, N), WTp (2c, N) W_N, W_T padded with zero columns
#: (core/contact_kkt.pad_rows).
Workspace = namedtuple("Workspace", "kv ka qs q_new v_new q_int v_int H dense_q dense_v q_old "
                                    "v_old span pk w w_new w_old dense_w pw M f s piv acc g WN WT coef rate r uf zero un "
                                    "mode law impact_law persistent touching coef_impact "
                                    "last_impact Y D sw power contact_stages stage_at quad_F "
                                    "quad_ends solver left_at bias slide slide_ref lcp_B lcp_C "
                                    "lcp_T lcp_z lcp_basis K x F xq phi gam crate G WNp WTp")


@njit
def workspace(kern, n):
    """Allocated once per run by adaptive.run_adaptive."""
    c, m = kern.N_CONTACTS, kern.N_CONSTRAINTS
    N = n + m
    nd = dop853.N_DENSE
    sw = events.Workspace(np.zeros(2 * c), np.zeros(2 * c), np.zeros(2 * c), np.zeros(2 * c),
                          np.zeros(2 * c, np.int64), np.zeros(n), np.zeros(n), np.zeros(1))
    return Workspace(np.zeros((nd, n)), np.zeros((nd, n)), np.zeros(n), np.zeros(n),
                     np.zeros(n), np.zeros(n), np.zeros(n), np.zeros((n, n)),
                     np.zeros((7, n)), np.zeros((7, n)), np.zeros(n), np.zeros(n), np.zeros(2),
                     *dop853.work_fields(n), np.zeros((n, n)), np.zeros(n), np.zeros(N),
                     np.zeros(N, np.int64),
                     np.zeros(n), np.zeros(c), np.zeros((c, n)), np.zeros((2 * c, n)),
                     np.zeros((c, 2)), np.zeros(3 * c), np.zeros(3 * c), np.zeros(3 * c),
                     np.zeros(c), np.zeros(c), np.zeros(c, np.int64), np.zeros(2 * c, np.int64),
                     np.zeros(2 * c, np.int64), np.zeros(c), np.zeros(c), np.zeros((c, 2)),
                     np.full(c, -np.inf), np.zeros((3 * c, N)), np.zeros((3 * c, 3 * c)), sw,
                     np.zeros(2), np.zeros((nd, 1)), np.zeros(1, np.int64), np.zeros((7, 1)),
                     np.zeros(2), np.zeros(4), np.full(c, -np.inf), np.zeros(3 * c),
                     np.zeros(2 * c), np.zeros(2 * c), *lcp_arrays(c),
                     np.zeros((N, N)), np.zeros(N), np.zeros(N), np.zeros(N), np.zeros(m),
                     np.zeros(m), np.zeros(m), np.zeros((m, n)), np.zeros((c, N)),
                     np.zeros((2 * c, N)))


@njit(inline="always")
def _kkt_and_rhs(kern, ws, q, v, t, p):
    """The KKT matrix K = [[M, -J^T], [J, 0]] at (q, t) LU-factored in ws.K, ws.piv (K = M
    without constraints), rhs into ws.f, Phi, J and gamma into ws.phi, ws.G, ws.gam; False when
    K is singular (M, or J M^-1 J^T: redundant constraints)."""
    n = kern.N_COORDS
    if kern.N_CONSTRAINTS == 0:      # K is M (n, n): no copy, no constraint kernel call
        kern.dynamics(q, v, t, p, ws.K, ws.f)
        return lu_inplace(ws.K, ws.piv)
    kern.dynamics(q, v, t, p, ws.M, ws.f)
    kern.constraints(q, v, t, p, ws.phi, ws.G, ws.gam)
    for i in range(n):
        for j in range(n):
            ws.K[i, j] = ws.M[i, j]
    assemble_constraint_rows(ws.K, n, ws.G, 0.0)
    return lu_inplace(ws.K, ws.piv)


@njit(inline="always")
def _local(ws, k, c, x):
    """W_k . x for row k of W (3c, n) (normal rows, then tangent 1 and tangent 2 rows)."""
    w = contact_row(k, c, ws.WN, ws.WT)
    s = 0.0
    for i in range(x.shape[0]):
        s += w[i] * x[i]
    return s


@njit(inline="always")
def _relative(ws, k, c, v):
    """The local velocity of row k relative to the surface, W_k v + b_k (ws.bias at the
    contacts' last evaluation)."""
    return _local(ws, k, c, v) + ws.bias[k]


@njit(inline="always")
def _contacts_at(kern, ws, q, t, p):
    """The contacts' gaps, Jacobians, coefficients and surface terms at (q, t) into ws."""
    kern.contacts(q, t, p, ws.g, ws.WN, ws.WT, ws.coef)
    kern.contact_bias(q, t, p, ws.bias)
    if kern.N_CONSTRAINTS > 0:
        pad_rows(kern.N_COORDS, ws.WN, ws.WT, ws.WNp, ws.WTp)


@njit(inline="always")
def _padded(kern, ws):
    """(W_N, W_T) with K's columns (c, N), (2c, N): the padded copies with constraints, the
    rows themselves without (N = n)."""
    if kern.N_CONSTRAINTS > 0:
        return ws.WNp, ws.WTp
    return ws.WN, ws.WT


@njit(inline="always")
def _has_pair(ws, a, c):
    """True when contact a has a second tangent (a non-zero tangent 2 row): the 3D cone."""
    w = ws.WT[c + a]
    for i in range(w.shape[0]):
        if w[i] != 0.0:
            return True
    return False


@njit(inline="always")
def _slip(ws, a, c, v):
    """(u_T1, u_T2) of contact a at velocity v, relative to the surface."""
    return _relative(ws, c + a, c, v), _relative(ws, 2 * c + a, c, v)


@njit(inline="always")
def _slide_directions(ws, c, v):
    """ws.slide: for each SLIDE contact the unit direction of its slip at v, oriented by
    sign(s_ref . u_T) (module docstring); s_ref itself where the slip is zero."""
    for a in range(c):
        if ws.mode[a] != SLIDE:
            continue
        u1, u2 = _slip(ws, a, c, v)
        r1, r2 = ws.slide_ref[a], ws.slide_ref[c + a]
        along = r1 * u1 + r2 * u2
        size = np.sqrt(u1 * u1 + u2 * u2)
        if along == 0.0 or size == 0.0:
            ws.slide[a], ws.slide[c + a] = r1, r2
        else:
            sign = 1.0 if along > 0.0 else -1.0
            ws.slide[a], ws.slide[c + a] = sign * u1 / size, sign * u2 / size


@njit(inline="always")
def _set_slide_ref(ws, a, c, d1, d2):
    """Contact a slides along (d1, d2) (normalized here; tangent 1 when it is zero)."""
    size = np.sqrt(d1 * d1 + d2 * d2)
    if size == 0.0:
        d1, d2, size = 1.0, 0.0, 1.0
    ws.slide_ref[a], ws.slide_ref[c + a] = d1 / size, d2 / size
    ws.slide[a], ws.slide[c + a] = d1 / size, d2 / size


@njit(inline="always")
def _solve(ws, c, tol, max_sweeps, flags, law, coef, un):
    """The contact problem on ws.D, ws.uf into ws.r: projected Gauss-Seidel, then Lemke's
    method when it stalls (core/contact_lcp.contact_solve). Returns the status."""
    status, _, _ = contact_solve(c, tol, max_sweeps, flags, law, coef, un, ws.uf, ws.D, ws.r,
                                 ws.slide, ws.lcp_B, ws.lcp_C, ws.lcp_T, ws.lcp_z,
                                 ws.lcp_basis)
    return status


@njit(inline="always")
def _apply(ws, c, flags, r, x):
    """x += sum_k Y_k r_k over the rows of the contacts flagged: x (n,) the velocities (the
    constraint impulses' part of Y left out) or x (N,) the KKT unknown (ws.x)."""
    for k in range(3 * c):
        if flags[k % c] != 0.0:
            for i in range(x.shape[0]):
                x[i] += ws.Y[k, i] * r[k]


@njit(**FAST)
def contact_acceleration(kern, ws, q, v, t, p, a):
    """a (n,) from M a = f + J^T lam + W^T lambda, J a = gamma (the constrained motion; a =
    M^-1 (f + W^T lambda) without constraints) with lambda (ws.r) the persistent contacts'
    forces under ws.law; ws.x (N,) <- (a, lam); ws.power[0] <- lambda . (W v). OK,
    SINGULAR_MASS, CONTACT_NOT_CONVERGED or CONTACT_NO_SOLUTION."""
    n, c, m = kern.N_COORDS, kern.N_CONTACTS, kern.N_CONSTRAINTS
    N = n + m
    if not _kkt_and_rhs(kern, ws, q, v, t, p):
        return SINGULAR_MASS
    x = ws.x
    for i in range(n):
        x[i] = ws.f[i]
    for k in range(m):       # no Baumgarte term: the drift of Phi is the integration error,
        x[n + k] = ws.gam[k]  # removed by the projection at each switch
    lu_solve_inplace(ws.K, ws.piv, x, ws.s)
    ws.power[0] = 0.0
    n_persistent = 0
    for k in range(c):
        n_persistent += int(ws.persistent[k])
    if n_persistent == 0:
        for i in range(n):
            a[i] = x[i]
        return OK
    _contacts_at(kern, ws, q, t, p)
    kern.contact_rates(q, v, t, p, ws.rate)
    WN, WT = _padded(kern, ws)
    delassus(c, N, ws.persistent, WN, WT, ws.K, ws.piv, ws.s, ws.Y, ws.D)
    for k in range(3 * c):
        ws.r[k] = 0.0
        ws.uf[k] = _local(ws, k, c, x[:n]) + ws.rate[k] if ws.persistent[k % c] != 0.0 else 0.0
    _slide_directions(ws, c, v)
    status = _solve(ws, c, ws.solver[0], int(ws.solver[1]), ws.persistent, ws.law, ws.coef,
                    ws.zero)
    if status != OK:
        return status
    _apply(ws, c, ws.persistent, ws.r, x)      # the multipliers follow the contact forces
    for i in range(n):
        a[i] = x[i]
    power = 0.0
    for k in range(3 * c):
        if ws.persistent[k % c] != 0.0:
            power += ws.r[k] * _local(ws, k, c, v)
    ws.power[0] = power
    return OK


@njit(**FAST)
def stage_acceleration(kern, ctx, q, v, t, a):
    """explicit_rk's callback: contact_acceleration; ctx = (p, ws). Records the persistent
    forces' power there as stage ws.stage_at of the step (attempt, accept, dense set it)."""
    p, ws = ctx
    status = contact_acceleration(kern, ws, q, v, t, p, a)
    k = ws.stage_at[0]
    if k < dop853.N_DENSE:
        ws.contact_stages[k, 0] = ws.power[0]
        ws.stage_at[0] = k + 1
    return status


@njit(**FAST)
def event_values(kern, ws, q, v, t, p, out):
    """The switching functions at (q, v, t) into out (2c,) (module docstring; each switches
    when it falls through 0): rows a < c the normal ones, c + a the tangent ones (1 when the
    contact has none). Leaves the contact forces in ws.r and their power in ws.power[0], the
    gaps at q in ws.g.

    A free contact that was touching at t_s = ws.left_at (it just bounced or lifted off) has
    g / (t - t_s) instead of g (u_N at t_s, its limit): g itself starts the step at 0 and
    would return below 0 within one long step (a parabola is one step of dop853) without a
    sign change; g / (t - t_s) is positive until the landing, where it crosses 0 with g."""
    c = kern.N_CONTACTS
    status = contact_acceleration(kern, ws, q, v, t, p, ws.acc)
    _contacts_at(kern, ws, q, t, p)
    for a in range(c):
        out[c + a] = 1.0
        if ws.mode[a] == FREE:
            out[a] = ws.g[a]
            if ws.left_at[a] == t:
                out[a] = _relative(ws, a, c, v)
            elif ws.left_at[a] > -np.inf:
                out[a] = ws.g[a] / (t - ws.left_at[a])
            continue
        out[a] = ws.r[a] if status == OK else 0.0
        if ws.coef[a, 1] > 0.0:
            if ws.mode[a] == STICK:
                out[c + a] = ws.coef[a, 1] * ws.r[a] - np.sqrt(ws.r[c + a] ** 2
                                                               + ws.r[2 * c + a] ** 2)
            elif ws.mode[a] == SLIDE:
                u1, u2 = _slip(ws, a, c, v)
                out[c + a] = ws.slide_ref[a] * u1 + ws.slide_ref[c + a] * u2
            elif ws.mode[a] == SLIDE_POSITIVE:
                out[c + a] = _relative(ws, c + a, c, v)
            else:
                out[c + a] = -_relative(ws, c + a, c, v)
    return status


@njit(**FAST)
def prepare(kern, q, v, t, p, settings, ws):
    """The solver settings into the workspace; every contact FREE until apply_switch
    classifies them (run_adaptive calls it next); stage 0 at the start state."""
    ws.solver[0] = settings.contact_tol
    ws.solver[1] = settings.max_sweeps
    ws.solver[2] = settings.gap_tol
    ws.solver[3] = 1.0           # the next apply_switch classifies the start state
    for a in range(kern.N_CONTACTS):
        ws.mode[a] = FREE
        ws.persistent[a] = 0.0
    dop853.start_work(kern, q, v, t, p, ws)
    return contact_acceleration(kern, ws, q, v, t, p, ws.ka[0])


@njit(**FAST)
def initial_step(kern, q, v, t, direction, p, settings, ws):
    """dop853's starting step: from ka[0] (the contact acceleration prepare wrote) and one
    contact-free evaluation (a guess of the scale only)."""
    return dop853.initial_step(kern, q, v, t, direction, p, settings, ws)


@njit(**FAST)
def attempt(kern, q, v, t, h, p, settings, ws):
    """dop853's trial step on the contact acceleration (dop853.attempt_on)."""
    ws.stage_at[0] = 1
    return dop853.attempt_on(_THIS, kern, (p, ws), p, q, v, t, h, settings, ws)


@njit(**FAST)
def accept(kern, t_new, p, ws):
    """dop853.accept_on: the FSAL stage on the contact acceleration."""
    ws.stage_at[0] = dop853.N_STAGES
    return dop853.accept_on(_THIS, kern, (p, ws), p, t_new, ws)


@njit(**FAST)
def dense(kern, q, v, t, h, p, ws):
    """dop853.dense_on: the dense output on the contact acceleration."""
    ws.stage_at[0] = dop853.N_STAGES + 1
    return dop853.dense_on(_THIS, kern, (p, ws), p, q, v, t, h, ws)


interpolate = dop853.interpolate
interpolate_work = dop853.interpolate_work
advance = dop853.advance


@njit(inline="always")
def _work_at(c):
    """Index of contact_work in extra."""
    return 1 + 4 * c


@njit(inline="always")
def _last_impact_at(c):
    """Index of last_impact (c) in extra."""
    return 2 + 4 * c


@njit(**FAST)
def switch_point(kern, ws, q, v, t, h, t_new, p, extra, counters):
    """After an accepted step from (q, v) at t to (ws.q_new, ws.v_new) at t_new: the switching
    functions there; on a crossing, the dense output, the earliest crossing time t* (refined)
    and the state there into ws.q_new, ws.v_new (and W into ws.w_new). Adds the persistent
    forces' work over [t, t_end of the step] to extra (from their power at the stages). Returns (status, switched, step end)."""
    c = kern.N_CONTACTS
    sw = ws.sw
    ws.contact_stages[0, 0] = ws.power[1]
    status = event_values(kern, ws, ws.q_new, ws.v_new, t_new, p, sw.g_new)
    if status != OK:
        return status, False, t_new
    crossed = False
    for k in range(2 * c):
        if events.crossing(sw.g_prev[k], sw.g_new[k], -1) != 0:
            crossed = True
    if not crossed:
        extra[_work_at(c)] += dop853.stage_integral(ws.contact_stages, h)
        ws.power[1] = ws.power[0]
        for k in range(2 * c):
            sw.g_prev[k] = sw.g_new[k]
        for a in range(c):           # a slide's reference: its slip direction at the new start
            if ws.mode[a] == SLIDE:
                u1, u2 = _slip(ws, a, c, ws.v_new)
                if u1 * ws.slide_ref[a] + u2 * ws.slide_ref[c + a] > 0.0:
                    _set_slide_ref(ws, a, c, u1, u2)
                    sw.g_prev[c + a] = np.sqrt(u1 * u1 + u2 * u2)
        for a in range(c):           # clear of the surface: the plain gap from here on
            if ws.left_at[a] > -np.inf and ws.g[a] > ws.solver[2]:
                ws.left_at[a] = -np.inf
                sw.g_prev[a] = ws.g[a]
        _record_constraints(kern, ws, ws.q_new, ws.v_new, t_new, p, extra)
        return OK, False, t_new
    status = dense(kern, q, v, t, h, p, ws)
    counters[3] += DENSE_EVALS
    if status != OK:
        return status, False, t_new
    t_star, first = t_new, -1
    for k in range(2 * c):
        if events.crossing(sw.g_prev[k], sw.g_new[k], -1) != 0:
            tk = events.refine(_THIS, ws, _THIS, kern, sw, p, k, t, sw.g_prev[k], t_new,
                               sw.g_new[k])
            if first < 0 or (tk - t_star) * (t_new - t) < 0.0:
                t_star, first = tk, k
    status, t_star = _past_crossing(kern, ws, p, t, t_new, first, t_star)
    if status != OK:
        return status, False, t_new
    if kern.WORK:                    # the step ends at t_star: W there from the dense output
        ws.w_new[0] = dop853.interpolate_work(ws, t_star)
    extra[_work_at(c)] += dop853.dense_integral(ws.contact_stages, h, (t_star - t) / h,
                                                 ws.quad_F, ws.quad_ends)
    _record_constraints(kern, ws, ws.q_new, ws.v_new, t_star, p, extra)
    return status, True, t_star


@njit(inline="always")
def _past_crossing(kern, ws, p, t, t_new, first, t_star):
    """The refined crossing t_star of function ``first`` moved, if needed, to where that
    function is <= 0 (refine returns the bracket end nearer the root, possibly on the positive
    side: the classification must see the switch done, or the run would switch again at once).
    The state there into ws.q_new, ws.v_new and the functions into sw.g_new. Returns
    (status, t_star)."""
    sw = ws.sw
    delta = events.ROOT_RTOL * abs(t_new - t) + 4.0 * events.EPS * abs(t_new)
    delta = delta if t_new > t else -delta
    status = OK
    for _ in range(64):
        dop853.interpolate(ws, t_star, ws.q_new, ws.v_new)
        status = event_values(kern, ws, ws.q_new, ws.v_new, t_star, p, sw.g_new)
        if sw.g_new[first] <= 0.0 or status != OK or t_star == t_new:
            break
        t_star = t_star + delta
        if (t_star - t_new) * delta > 0.0:
            t_star = t_new
        delta *= 2.0
    return status, t_star


@njit(inline="always")
def _impact(kern, ws, v, t, settings, extra):
    """Newton's impact law with Coulomb friction on the touching contacts (ws.touching) at
    velocity v (n,), in place; ws.K holds the factored KKT matrix (the mass matrix without
    constraints: the impulses act on the constrained motion, J v kept), WN, WT (and their padded
    copies), coef the contacts. The Zeno guard sets e = 0 for a contact hit again within
    zeno_interval. Returns status."""
    c = kern.N_CONTACTS
    N = kern.N_COORDS + kern.N_CONSTRAINTS
    WN, WT = _padded(kern, ws)
    delassus(c, N, ws.touching, WN, WT, ws.K, ws.piv, ws.s, ws.Y, ws.D)
    for a in range(c):
        ws.coef_impact[a, 0] = ws.coef[a, 0]
        ws.coef_impact[a, 1] = ws.coef[a, 1]
        ws.un[a] = _relative(ws, a, c, v)
        if ws.touching[a] != 0.0 and t - ws.last_impact[a] < settings.zeno_interval:
            ws.coef_impact[a, 0] = 0.0
    for k in range(3 * c):
        ws.r[k] = 0.0
        ws.uf[k] = _relative(ws, k, c, v) if ws.touching[k % c] != 0.0 else 0.0
    status = _solve(ws, c, settings.contact_tol, settings.max_sweeps, ws.touching,
                    ws.impact_law, ws.coef_impact, ws.un)
    if status != OK:
        return status
    _record_impulses(kern, ws, ws.touching, v, extra)
    for a in range(c):
        if ws.touching[a] != 0.0 and ws.r[a] > 0.0:
            ws.last_impact[a] = t
            extra[_last_impact_at(c) + a] = t
    extra[IMPACTS] += 1.0
    return OK


@njit(inline="always")
def _record_impulses(kern, ws, flags, v, extra):
    """v += M^-1 W^T r over the flagged contacts (the velocity part of K^-1 [W^T r; 0] with
    constraints); the impulses' sums and their work r . (u- + u+) / 2 into extra."""
    c = kern.N_CONTACTS
    work = 0.0
    for k in range(3 * c):
        if flags[k % c] != 0.0:
            work += 0.5 * ws.r[k] * _local(ws, k, c, v)
    _apply(ws, c, flags, ws.r, v)
    for k in range(3 * c):
        if flags[k % c] != 0.0:
            work += 0.5 * ws.r[k] * _local(ws, k, c, v)
            extra[1 + k] += ws.r[k]
    extra[_work_at(c)] += work


@njit(inline="always")
def _set_modes(kern, ws, q, v, t, p, settings):
    """Modes of the touching contacts at rest (module docstring, step 2): persistent when the
    force at the acceleration level is positive, sticking when that fits the cone. Returns
    status."""
    c = kern.N_CONTACTS
    for a in range(c):
        rest = ws.touching[a] != 0.0 and abs(_relative(ws, a, c, v)) <= settings.rest_velocity
        ws.persistent[a] = 1.0 if rest else 0.0
        ws.mode[a] = FREE
        ws.law[a] = BILATERAL
        ws.law[c + a] = STICK
        if rest:
            ws.mode[a] = STICK
            if _has_pair(ws, a, c):
                u1, u2 = _slip(ws, a, c, v)
                if ws.coef[a, 1] > 0.0 and np.sqrt(u1 * u1 + u2 * u2) > settings.rest_velocity:
                    ws.mode[a] = SLIDE
                    _set_slide_ref(ws, a, c, u1, u2)
            else:
                ut = _relative(ws, c + a, c, v)
                if ws.coef[a, 1] > 0.0 and abs(ut) > settings.rest_velocity:
                    ws.mode[a] = SLIDE_POSITIVE if ut > 0.0 else SLIDE_NEGATIVE
            ws.law[c + a] = ws.mode[a]
    status = OK
    for _ in range(2 * c + 1):          # each pass frees or starts sliding one contact at least
        status = contact_acceleration(kern, ws, q, v, t, p, ws.acc)
        if status != OK:
            return status
        changed = False
        for a in range(c):
            if ws.persistent[a] == 0.0:
                continue
            if ws.r[a] <= 0.0:
                ws.persistent[a], ws.mode[a], changed = 0.0, FREE, True
            elif ws.mode[a] == STICK and (np.sqrt(ws.r[c + a] ** 2 + ws.r[2 * c + a] ** 2)
                                          > ws.coef[a, 1] * ws.r[a]):
                # it slides away from the sticking force
                if _has_pair(ws, a, c):
                    ws.mode[a] = SLIDE
                    _set_slide_ref(ws, a, c, -ws.r[c + a], -ws.r[2 * c + a])
                else:
                    ws.mode[a] = SLIDE_POSITIVE if ws.r[c + a] < 0.0 else SLIDE_NEGATIVE
                ws.law[c + a], changed = ws.mode[a], True
        if not changed:
            break
    return status


@njit(**FAST)
def apply_switch(kern, ws, q, v, t, p, settings, extra):
    """Classify the contacts at (q, v, t) and continue from there (module docstring: the
    impact, the modes, the projection onto the persistent rows); v changes in place. Then the
    first stage ka[0], the switching functions and the power at the new start. Returns
    status."""
    n, c, m = kern.N_COORDS, kern.N_CONTACTS, kern.N_CONSTRAINTS
    work_before = extra[_work_at(c)]
    if ws.solver[3] != 0.0:        # a call's start: the Zeno guard's memory from extra
        for a in range(c):
            if extra[IMPACTS] == 0.0:      # none yet (extra starts at zeros)
                extra[_last_impact_at(c) + a] = -np.inf
            ws.last_impact[a] = extra[_last_impact_at(c) + a]
    if m > 0:                      # the integration's drift off Phi = 0 removed here
        status = _project_positions(kern, ws, q, v, t, p)
        if status != OK:
            return status
    if not _kkt_and_rhs(kern, ws, q, v, t, p):
        return SINGULAR_MASS
    if m > 0:                      # and off J v + dPhi/dt = 0
        _project_velocities(kern, ws, q, v, t, p)
    _contacts_at(kern, ws, q, t, p)
    approaching = False
    for a in range(c):
        un = _relative(ws, a, c, v)
        touching = ws.g[a] <= settings.gap_tol and un <= settings.rest_velocity
        ws.touching[a] = 1.0 if touching else 0.0
        approaching = approaching or (touching and un < -settings.rest_velocity)
    if approaching:
        status = _impact(kern, ws, v, t, settings, extra)
        if status != OK:
            return status
    status = _set_modes(kern, ws, q, v, t, p, settings)
    if status != OK:
        return status
    n_persistent = 0
    for a in range(c):
        n_persistent += int(ws.persistent[a])
    if n_persistent > 0:     # rest stays rest: u_N = 0 (and u_T = 0 sticking) on the velocities
        if not _kkt_and_rhs(kern, ws, q, v, t, p):
            return SINGULAR_MASS
        _contacts_at(kern, ws, q, t, p)
        WN, WT = _padded(kern, ws)
        delassus(c, n + m, ws.persistent, WN, WT, ws.K, ws.piv, ws.s, ws.Y, ws.D)
        for k in range(3 * c):
            ws.r[k] = 0.0
            ws.uf[k] = _relative(ws, k, c, v) if ws.persistent[k % c] != 0.0 else 0.0
        _slide_directions(ws, c, v)
        status = _solve(ws, c, settings.contact_tol, settings.max_sweeps, ws.persistent,
                        ws.law, ws.coef, ws.zero)
        if status != OK:
            return status
        _record_impulses(kern, ws, ws.persistent, v, extra)
    if ws.solver[3] != 0.0:        # row 0 is the state after this: the work counts from it
        extra[_work_at(c)] = work_before
        ws.solver[3] = 0.0
    for a in range(c):
        extra[1 + 3 * c + a] = ws.mode[a]
        ws.left_at[a] = t if ws.mode[a] == FREE and ws.g[a] <= settings.gap_tol else -np.inf
    status = event_values(kern, ws, q, v, t, p, ws.sw.g_prev)
    ws.power[1] = ws.power[0]
    if status != OK:
        return status
    dop853.start_work(kern, q, v, t, p, ws)      # P at the velocities after the impulses
    status = contact_acceleration(kern, ws, q, v, t, p, ws.ka[0])
    _record_constraints(kern, ws, q, v, t, p, extra)
    return status


@njit(inline="always")
def _record_constraints(kern, ws, q, v, t, p, extra):
    """The constrained fields of extra (nothing without constraints): the multipliers lam
    (ws.x[n:], left there by contact_acceleration at (q, v, t), as ws.phi and ws.G), max|Phi|
    and max|J v + dPhi/dt|."""
    if kern.N_CONSTRAINTS > 0:
        constraint_rate(kern, q, t, p, ws.crate)
        record_constraints(extra, _constraints_at(kern.N_CONTACTS), ws.x, kern.N_COORDS, 1.0,
                           ws.phi, ws.G, v, ws.crate)


@njit(inline="always")
def _constraints_at(c):
    """Index of the constrained fields (multipliers (m), constraint_error,
    velocity_constraint_error) in extra: after last_impact (c)."""
    return 2 + 5 * c


@njit(inline="always")
def assemble_projection(kern, args, x, F, J):
    """Newton system of the position projection at a switch: x = (q (n,), mu (m,)),
    F = (M (q - q_ref) - J(q)^T mu, Phi(q, t)), the point of Phi = 0 nearest q_ref in the
    kinetic-energy metric M = M(q) (the last iterate's). Its Jacobian is taken as the KKT matrix
    [[M, -J^T], [J, 0]] at q: the terms left out (dM/dq (q - q_ref), d(J^T mu)/dq) are of the
    size of the drift, which is the integration error, so the iteration still converges in a
    step or two."""
    ws, q_ref, v, t, p = args
    n, m = kern.N_COORDS, kern.N_CONSTRAINTS
    q = x[:n]
    kern.mass_matrix(q, t, p, ws.M)
    kern.constraints(q, v, t, p, ws.phi, ws.G, ws.gam)
    for i in range(n):
        s = 0.0
        for j in range(n):
            s += ws.M[i, j] * (q[j] - q_ref[j])
            J[i, j] = ws.M[i, j]
        for k in range(m):
            s -= ws.G[k, i] * x[n + k]
        F[i] = s
    for k in range(m):
        F[n + k] = ws.phi[k]
    assemble_constraint_rows(J, n, ws.G, 0.0)


@njit(inline="always")
def _project_positions(kern, ws, q, v, t, p):
    """q (n,) <- the point of Phi(q, t) = 0 nearest q in the metric of M (Newton,
    assemble_projection; ws.qs holds q_ref, ws.xq the unknown). Returns status (OK, or
    Newton's failure: NEWTON_DIVERGED, SINGULAR_NEWTON, NON_FINITE)."""
    n, m = kern.N_COORDS, kern.N_CONSTRAINTS
    x = ws.xq
    for i in range(n):
        ws.qs[i] = q[i]
        x[i] = q[i]
    for k in range(m):
        x[n + k] = 0.0
    status, _, _ = newton.solve(_PROJECTION, kern, (ws, ws.qs, v, t, p), x, ws.F, ws.K, ws.piv,
                                ws.s, PROJECTION_TOL, PROJECTION_MAX_ITER, n + m)
    if status != OK:
        return status
    for i in range(n):
        q[i] = x[i]
    return OK


@njit(inline="always")
def _project_velocities(kern, ws, q, v, t, p):
    """v (n,) <- v + dv with J dv = -(J v + dPhi/dt), M dv = J^T nu: the velocity on the
    constraints nearest v in the kinetic-energy metric. ws.K, ws.G hold the factored KKT
    matrix and J at (q, t) (_kkt_and_rhs)."""
    n, m = kern.N_COORDS, kern.N_CONSTRAINTS
    constraint_rate(kern, q, t, p, ws.crate)
    x = ws.x
    for i in range(n):
        x[i] = 0.0
    for k in range(m):
        s = -ws.crate[k]
        for j in range(n):
            s -= ws.G[k, j] * v[j]
        x[n + k] = s
    lu_solve_inplace(ws.K, ws.piv, x, ws.s)
    for i in range(n):
        v[i] += x[i]


# This module as a value for rk_step and events.refine (modules, not dispatchers, are passed).
_THIS = sys.modules[__name__]
# The position projection's Newton system, as a module for newton.solve (see newton.py).
_PROJECTION = newton.problem(__name__ + "._projection", assemble_projection)

SPEC = Spec(
    name="dop853_impacts", order=8, family="nonsmooth", implicit=False, symplectic=False,
    symmetric=False, adaptive=True, contacts=True, holonomic_too=True,
    constraint_drift="grows",
    summary="event-driven contacts: dop853 between located impacts (Newton's law), "
            "persistent contacts and stick-slip switches, Zeno guard",
    settings=Settings,
    saved=(("impacts", 1), ("normal_impulse_sum", "c"), ("tangent_impulse_sum", "c"),
           ("tangent2_impulse_sum", "c"), ("contact_mode", "c"), ("contact_work", 1),
           ("last_impact", "c"), ("multipliers", "m"), ("constraint_error", "m1"),
           ("velocity_constraint_error", "m1")),
    limits={"rtol": (100 * 2.220446049250313e-16, True, False), "atol": (0.0, False, False),
            "h_max": (0.0, False, True), "max_steps": (1, True, False),
            "zeno_interval": (0.0, True, False), "gap_tol": (0.0, True, False),
            "rest_velocity": (0.0, True, False), "contact_tol": (0.0, False, False),
            "max_sweeps": (1, True, False)},
    kernels=("constraint_rate", "constraints", "contacts", "contact_bias", "contact_rates",
             "dynamics", "forward_dynamics", "mass_matrix", "power"))
