"""The check of a state after every step: finite, and within the blow-up bound."""

import math

import numpy as np
from ...jit.cache import njit

from .options import FAST
from .status import NON_FINITE, OK, UNSTABLE


@njit(cache=True, **FAST)
def check_state(q, v, bound):
    """NON_FINITE if any entry is NaN/inf, UNSTABLE if one exceeds bound, else OK.

    Runs after every step: one comparison per entry (NaN fails it too), the failing case sorted
    out by _classify. max_abs over q and v instead (a branch on NaN per entry) would add about
    a tenth to an explicit Euler step on the cart pendulum."""
    limit = min(bound, _LARGEST)       # a bound of inf must still stop at inf
    for i in range(q.shape[0]):
        if not (abs(q[i]) <= limit and abs(v[i]) <= limit):
            return _classify(q, v)
    return OK


_LARGEST = np.finfo(np.float64).max


@njit(cache=True, **FAST)
def _classify(q, v):
    """check_state's verdict on a state that failed its comparison: NON_FINITE when an entry is
    NaN or inf, else UNSTABLE. (Each entry is tested: max(max_abs(q), max_abs(v)) drops a NaN of
    v behind a finite max of q, since max(a, NaN) is a.)"""
    for i in range(q.shape[0]):
        if not (math.isfinite(q[i]) and math.isfinite(v[i])):
            return NON_FINITE
    return UNSTABLE
