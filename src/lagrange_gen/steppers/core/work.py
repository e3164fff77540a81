"""The work W of non-conservative forces, dissipation and explicit time, integrated by the run
loop so that the energy balance E(t) - E(t0) - W(t) = 0 can be checked on any model.

With E = T2 - T0 + V (the energy function, generated ``energy``), dE/dt = P along a motion,
P = qd . Q_nc - dL/dt (generated ``power``, which also gives dP/dq, dP/dqd and dP/dt). Over a
step from t to t + h the loop adds the corrected trapezoid (Euler-Maclaurin) rule

    W += h/2 (P0 + P1) + h^2/12 (P0' - P1'),    P' = dP/dq . v + dP/dqd . a + dP/dt,

exact for cubic P(t), error O(h^5) per step: the balance closes to O(h^min(p, 4)) for a method of
order p (the plain trapezoid would cap it at O(h^2)). The acceleration a comes from forward
dynamics (one extra Cholesky solve per step on a model with WORK); on a constrained model the
constraint force is not in it, so there the h^2 term is left out (trapezoid, order 2, the order
of rattle and constrained_midpoint). Not included: the work of the constraint forces of
rheonomic constraints (-lam . dPhi/dt).

Nonsmooth elements (nonsmooth_euler, order 1): the trajectory's E includes the elastic energy
k u^2 / 2 of the Saint-Venant elements, so W also takes what the elements dissipate. Over a step
with strain increment ds = s(q+) - s(q) and the states u (before) and u+ (after) the return map,
a Saint-Venant element dissipates k u+ (ds - (u+ - u)) >= 0 (zero while elastic, k eta |ds|
while sliding) and a friction element with force r (its state) does the work r ds <= 0; both
are the exact energy bookkeeping of the backward-Euler step of the element.

Only models with kern.WORK (P not identically zero) pay for any of it; the loop guards every
call with that generated constant.
"""

from collections import namedtuple

import numpy as np
from ...jit.cache import njit

from .options import FAST

Workspace = namedtuple("Workspace", "pw H a s0 u0 s1 G coef")


@njit
def workspace(kern, n):
    """pw (2n + 2,) the power kernel's output, H (n, n), a (n,) for the acceleration; for the
    elements (ne,) strains s0 at the start and s1 at the end of a step and states u0 at its
    start, G (ne, n) and coef (ne, 3) the elements kernel's other outputs."""
    ne = kern.N_ELEMENTS
    return Workspace(np.zeros(2 * n + 2), np.zeros((n, n)), np.zeros(n), np.zeros(ne),
                     np.zeros(ne), np.zeros(ne), np.zeros((ne, n)), np.zeros((ne, 3)))


@njit(**FAST)
def rate(kern, ww, q, v, t, p):
    """(P, dP/dt) at (q, v, t); dP/dt = 0 on constrained models (see the module docstring)."""
    n = q.shape[0]
    pw = ww.pw
    kern.power(q, v, t, p, pw)
    if kern.N_CONSTRAINTS > 0:
        return pw[0], 0.0
    kern.forward_dynamics(q, v, t, p, ww.H, ww.a)    # a singular H: the step already said so
    d = pw[2 * n + 1]
    for i in range(n):
        d += pw[1 + i] * v[i] + pw[1 + n + i] * ww.a[i]
    return pw[0], d


@njit(**FAST)
def increment(h, P0, D0, P1, D1):
    """The corrected trapezoid rule over one step of size h."""
    return 0.5 * h * (P0 + P1) + h * h / 12.0 * (D0 - D1)


@njit(**FAST)
def elements_begin(kern, ww, q, p, state):
    """Before a step: the strains at q and the element states (ne,) it starts from."""
    kern.elements(q, p, ww.s0, ww.G, ww.coef)
    for e in range(state.shape[0]):
        ww.u0[e] = state[e]


@njit(**FAST)
def elements_increment(kern, ww, q, p, state):
    """After a step to q with the element states (ne,) it produced: minus the energy the
    elements dissipated over it (module docstring)."""
    kern.elements(q, p, ww.s1, ww.G, ww.coef)
    w = 0.0
    for e in range(state.shape[0]):
        ds = ww.s1[e] - ww.s0[e]
        if ww.coef[e, 2] == 0.0:         # Saint-Venant: the plastic part of ds
            w -= ww.coef[e, 0] * state[e] * (ds - (state[e] - ww.u0[e]))
        else:                            # dry friction: the force r does r ds
            w += state[e] * ds
    return w
