"""The Saint-Venant return map and the play operator it defines.

A Saint-Venant element with threshold eta has an internal variable u (its elastic strain) with
u' + dpsi_[-eta, eta](u) ∋ s'. Backward Euler of this inclusion over a strain increment ds is the
projection u+ = clamp(u + ds, -eta, eta): exact whatever the increment, since the solution of the
inclusion for a strain moving monotonically over one step is exactly that projection. Driven by
a prescribed strain path this is the play (backlash) operator; the element force is k u.
"""

import numpy as np
from ..jit import NO_REFCOUNT, njit


@njit(cache=True, **NO_REFCOUNT)
def return_map(u, ds, eta):
    """u+ = clamp(u + ds, -eta, eta) (scalars)."""
    return min(max(u + ds, -eta), eta)


@njit(cache=True)
def _play(s, eta, u0, out):
    u = u0
    out[0] = u
    for i in range(1, s.shape[0]):
        u = return_map(u, s[i] - s[i - 1], eta)
        out[i] = u


def play_operator(s, eta, u0=0.0):
    """Elastic strain u (N,) of a Saint-Venant element driven by the strain path s (N,)."""
    s = np.ascontiguousarray(s, dtype=np.float64)
    if not eta > 0:
        raise ValueError(f"play_operator: threshold eta must be > 0, got {eta}")
    out = np.empty_like(s)
    _play(s, float(eta), float(u0), out)
    return out


def loop_area(x, y):
    """Signed area enclosed by the closed polygon (x, y) (shoelace formula); counterclockwise > 0."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))
