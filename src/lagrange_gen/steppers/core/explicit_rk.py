"""One explicit Runge-Kutta step on (q, v) for any explicit Butcher tableau.

The second-order system q' = v, v' = a(q, v, t) as a first-order ODE in (q, v), s stages:

    Q_i = q + h sum_{j<i} A_ij V_j,   V_i = v + h sum_{j<i} A_ij a_j,   a_i = a(Q_i, V_i, t + c_i h)
    q+  = q + h sum_i b_i V_i,        v+  = v + h sum_i b_i a_i

A (s, s) strictly lower triangular, b (s,), c (s,) with c_i = sum_j A_ij. The tableaux below are
module-level numpy constants: numba freezes a global array into the compiled code, so they cost
nothing to pass and keep the glue cacheable.

Where the acceleration comes from is the caller's business: ``source`` is a module (a compile-time
constant for numba, like the ``method`` of run_loop.run_loop) defining

    stage_acceleration(kern, ctx, q, v, t, a) -> status      (jitted, writes a (n,), no allocation)

and ``ctx`` a tuple of whatever that function needs besides the state (parameters, workspace
views, settings), built once per step by the caller. rk4 plugs in the generated forward dynamics,
index1 the KKT solve of the acceleration-level constrained system.
"""

import numpy as np
from ...jit.cache import njit

from .options import FAST
from .status import OK

#: The classical fourth-order method (Kutta 1901).
RK4_A = np.array([[0.0, 0.0, 0.0, 0.0],
                  [0.5, 0.0, 0.0, 0.0],
                  [0.0, 0.5, 0.0, 0.0],
                  [0.0, 0.0, 1.0, 0.0]])
RK4_B = np.array([1.0 / 6.0, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 6.0])
RK4_C = np.array([0.0, 0.5, 0.5, 1.0])

#: Kutta's 3/8 rule, also order 4 (the second fourth-order method of Kutta's paper).
RULE38_A = np.array([[0.0, 0.0, 0.0, 0.0],
                     [1.0 / 3.0, 0.0, 0.0, 0.0],
                     [-1.0 / 3.0, 1.0, 0.0, 0.0],
                     [1.0, -1.0, 1.0, 0.0]])
RULE38_B = np.array([0.125, 0.375, 0.375, 0.125])
RULE38_C = np.array([0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0])

#: Heun's method (explicit trapezoidal rule), order 2.
HEUN_A = np.array([[0.0, 0.0],
                   [1.0, 0.0]])
HEUN_B = np.array([0.5, 0.5])
HEUN_C = np.array([0.0, 1.0])


@njit(inline="always", **FAST)
def stage_state(A, i, q, v, h, stage_v, stage_a, qs, n):
    """Q_i into qs (n,) and V_i into stage_v[i] (n,) from the stages j < i. Zero entries of A
    are skipped: no work for them, and a non-finite stage cannot leak through a 0 coefficient.
    n passed: kern.N_COORDS (core/options.py, "Loop bounds")."""
    vi = stage_v[i]
    for k in range(n):
        sq = 0.0
        sv = 0.0
        for j in range(i):
            if A[i, j] != 0.0:
                sq += A[i, j] * stage_v[j, k]
                sv += A[i, j] * stage_a[j, k]
        qs[k] = q[k] + h * sq
        vi[k] = v[k] + h * sv


@njit(inline="always", **FAST)
def rk_step(source, kern, ctx, A, b, c, q, v, t, h, stage_v, stage_a, qs, q_out, v_out,
            first_known):
    """One step of the tableau (A, b, c) from (q, v) at t; the new state goes to q_out, v_out.

    stage_v, stage_a (s', n) with s' >= s: stage velocities V_i and accelerations a_i (arrays of
    the caller's workspace); qs (n,) scratch. first_known: stage_a[0] already holds a(q, v, t)
    (cached by the caller, e.g. from the end of the previous step), so it is not evaluated.
    q_out, v_out (n,) may be q, v themselves (each entry k is written after its last read).
    Returns OK or the first non-OK status of source.stage_acceleration; then q_out, v_out are
    untouched."""
    n, s = kern.N_COORDS, b.shape[0]       # (n: options.py, "Loop bounds")
    for i in range(s):
        stage_state(A, i, q, v, h, stage_v, stage_a, qs, n)
        if i == 0 and first_known:
            continue
        status = source.stage_acceleration(kern, ctx, qs, stage_v[i], t + c[i] * h, stage_a[i])
        if status != OK:
            return status
    for k in range(n):
        sq = 0.0
        sv = 0.0
        for i in range(s):
            sq += b[i] * stage_v[i, k]
            sv += b[i] * stage_a[i, k]
        q_out[k] = q[k] + h * sq
        v_out[k] = v[k] + h * sv
    return OK
