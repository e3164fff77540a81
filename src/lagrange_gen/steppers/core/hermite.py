"""Interpolation of a fixed step for event location (steppers/core/events.py): Hermite polynomials
through the states at both ends of the step.

The interpolation interface every stepper family provides to events.locate (dop853.py gives
its dense output the same signature)::

    interpolate(ws, t, q_out, v_out)     q_out, v_out (n,) <- the state at time t of the step

With the accelerations a = H^-1 rhs at both ends (models without constraints or nonsmooth
elements; legendre.accel), q is the quintic Hermite polynomial through (q, v, a) at both ends and v
its derivative: local error O(h^6) in q and O(h^5) in v, below the global error of every
fixed-step method, so the located event times converge at the order of the method. On a
constrained model (multiplier forces) or one with elements (element forces), H^-1 rhs is not the
acceleration, so q is the cubic Hermite polynomial through (q, v) at both ends and v its
derivative (O(h^4) and O(h^3)). In both cases v = dq/dt of the interpolant.

The accelerations are computed by ``fit``, called only for a step in which an event function
changed sign: the step loop pays one copy of (q, v) per step (``begin``) and nothing else.
Shapes: n coordinates; q, v (n,).
"""

from collections import namedtuple

import numpy as np
from ...jit.cache import njit

from .legendre import accel

from .options import FAST

from .solve import copy_into
from .status import OK

#: The data of one step: span (2,) = [t at the start, step h]; the states (q0, v0) at the
#: start and (q1, v1) at the end, accelerations a0, a1 (n,); quintic (1,) int64 = 1 when a0, a1
#: are the accelerations (quintic in q), 0 when not available (cubic); H (n, n) scratch.
Workspace = namedtuple("Workspace", "span q0 v0 a0 q1 v1 a1 quintic H")


@njit
def workspace(n):
    """Allocated once per run by the step loop."""
    return Workspace(np.zeros(2), np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n),
                     np.zeros(n), np.zeros(n), np.zeros(1, np.int64), np.zeros((n, n)))


@njit(**FAST)
def begin(ws, q, v):
    """Keep the state (q, v) at the start of a step (the stepper overwrites q, v in place)."""
    copy_into(ws.q0, q)
    copy_into(ws.v0, v)


@njit(**FAST)
def fit(kern, ws, t0, t1, q1, v1, p):
    """Complete the step from t0 (state kept by ``begin``) to t1 with end state (q1, v1): the
    accelerations at both ends when the model allows (see the module docstring)."""
    ws.span[0] = t0
    ws.span[1] = t1 - t0
    copy_into(ws.q1, q1)
    copy_into(ws.v1, v1)
    ws.quintic[0] = 0
    if kern.N_CONSTRAINTS == 0 and kern.N_ELEMENTS == 0:
        if (accel(kern, ws.q0, ws.v0, t0, p, ws.H, ws.a0) == OK
                and accel(kern, ws.q1, ws.v1, t1, p, ws.H, ws.a1) == OK):
            ws.quintic[0] = 1


@njit(**FAST)
def interpolate(ws, t, q_out, v_out):
    """q_out, v_out (n,) <- the interpolated state at time t (inside the step)."""
    h = ws.span[1]
    s = (t - ws.span[0]) / h
    s2 = s * s
    s3 = s2 * s
    if ws.quintic[0] == 1:
        s4 = s3 * s
        s5 = s4 * s
        # Quintic Hermite basis on [0, 1] and its derivatives (values, slopes, curvatures).
        b0, b1 = 1.0 - 10.0 * s3 + 15.0 * s4 - 6.0 * s5, s - 6.0 * s3 + 8.0 * s4 - 3.0 * s5
        b2, b3 = 0.5 * (s2 - 3.0 * s3 + 3.0 * s4 - s5), 0.5 * (s3 - 2.0 * s4 + s5)
        b4, b5 = -4.0 * s3 + 7.0 * s4 - 3.0 * s5, 10.0 * s3 - 15.0 * s4 + 6.0 * s5
        d0, d1 = -30.0 * (s2 - 2.0 * s3 + s4), 1.0 - 18.0 * s2 + 32.0 * s3 - 15.0 * s4
        d2 = 0.5 * (2.0 * s - 9.0 * s2 + 12.0 * s3 - 5.0 * s4)
        d3 = 0.5 * (3.0 * s2 - 8.0 * s3 + 5.0 * s4)
        d4 = -12.0 * s2 + 28.0 * s3 - 15.0 * s4
        hh = h * h
        for i in range(q_out.shape[0]):
            q0, q1 = ws.q0[i], ws.q1[i]
            hv0, hv1, ha0, ha1 = h * ws.v0[i], h * ws.v1[i], hh * ws.a0[i], hh * ws.a1[i]
            q_out[i] = b0 * q0 + b1 * hv0 + b2 * ha0 + b3 * ha1 + b4 * hv1 + b5 * q1
            v_out[i] = (d0 * (q0 - q1) + d1 * hv0 + d2 * ha0 + d3 * ha1 + d4 * hv1) / h
        return
    # Cubic Hermite basis (d5 = -d0: the derivatives of the value weights sum to zero).
    c0, c1, c3, c2 = 1.0 - 3.0 * s2 + 2.0 * s3, s - 2.0 * s2 + s3, s3 - s2, 3.0 * s2 - 2.0 * s3
    e0, e1, e3 = 6.0 * (s2 - s), 1.0 - 4.0 * s + 3.0 * s2, 3.0 * s2 - 2.0 * s
    for i in range(q_out.shape[0]):
        q0, q1, hv0, hv1 = ws.q0[i], ws.q1[i], h * ws.v0[i], h * ws.v1[i]
        q_out[i] = c0 * q0 + c1 * hv0 + c3 * hv1 + c2 * q1
        v_out[i] = (e0 * (q0 - q1) + e1 * hv0 + e3 * hv1) / h
