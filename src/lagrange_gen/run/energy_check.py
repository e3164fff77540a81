"""The energy warning of simulate: a conservative run that lost its energy says so, in one line.

A run with too large a step can end with exit 0 and a plausible-looking trajectory whose energy
is off by orders of magnitude (midpoint at h = 2 on the cart pendulum: max|E - E0| = 1e10).
On a model whose energy is an invariant of the flow, ``energy_warning`` returns one line when

    max_k |E_k - E_0| > ENERGY_FRACTION * scale,    scale = max_k T_k + (max_k V_k - min_k V_k)

over the saved states (at most SCALE_ROWS of them, evenly spaced). The scale is the energy the
motion exchanges between T and V; unlike E0 it does not depend on the arbitrary zero of V, and
along any run |E_k - E_0| <= |T_k - T_0| + |V_k - V_0| <= scale, so the ratio lies in [0, 1]:
a blown-up run sits near 1 (its own T is huge), an accurate one near 0. ENERGY_FRACTION = 0.1: an
error of a tenth of the exchanged energy changes amplitudes by about 5 % (sqrt(1.1)), past any
deliberate coarse step; smaller bounded errors of symplectic methods are not warned about.

The line gives tau = h omega_max at q0, from K v = omega^2 H v with K = dg/dq (the Hessian of V)
by central differences of the generated ``dynamics`` at qd = 0 (there rhs = -g(q)), and the
method's stable range (steppers.registry.INFO).

Conservative (``is_conservative``): no nonsmooth elements, no constraints, and the power of
everything but T and V vanishes, dE/dt = dE/dq . v + dE/dv . a + dE/dt = 0 along the generated
forward dynamics, by central differences at a few states drawn around (q0, v0). This treats
gyroscopic forces (no power) as conservative and any force, dissipation or explicit time
dependence with power as not; a model left undecided (every sample singular) gets no warning.
"""

from __future__ import annotations

import math
import sys

import numpy as np

from ..jit.python_calls import unchecked
from ..steppers.core.status import OK

ENERGY_FRACTION = 0.1
SCALE_ROWS = 1001
#: |dE/dt| relative to the sum of its three terms' sizes below which a sample counts as
#: conserving energy (central differences are good to about 1e-8 here).
POWER_RTOL = 1e-6
_SAMPLES = 4
#: Rows of the first, lower-bound estimate of the scale (energy_warning).
FEW_ROWS = 17


def energy_warning(module, method, q, v, t, energy, p, h, advice="reduce h"):
    """One line (str) or None. q, v (S, n), t (S,), energy (S,) of a finished unconstrained run,
    p (n_params,), h the step (an adaptive run: its mean step), advice what to change."""
    # max |E_k - E_0| = max(max E - E_0, E_0 - min E): rounding is monotone, so the same
    # number as the largest rounded difference, without a temporary array; on a few rows in
    # Python floats (a numpy reduction costs more than the comparisons it does).
    if len(energy) <= FEW_ROWS:
        values = energy.tolist()
        if math.isnan(sum(values)):           # as numpy's max would: NaN, and no warning
            return None
        e0, high, low = values[0], max(values), min(values)
    else:
        e0, high, low = float(energy[0]), float(energy.max()), float(energy.min())
    err = max(high - e0, e0 - low)
    floor = 64 * sys.float_info.epsilon * max(abs(high), abs(low))
    if not err > floor:
        return None
    # Cheapest first. The scale over a few rows is at most the scale over all of them (a max
    # and a range over a subset), so an error below the fraction of it is below the fraction
    # of the whole scale: an accurate run is decided by FEW_ROWS kernel calls. Then
    # is_conservative (a few dozen kernel calls), then the scale over up to SCALE_ROWS rows.
    if not err > ENERGY_FRACTION * energy_scale(module, q, t, energy, p, FEW_ROWS):
        return None
    if not is_conservative(module, q[0], v[0], t[0], p):
        return None
    scale = energy_scale(module, q, t, energy, p)
    if not err > ENERGY_FRACTION * scale:
        return None
    from ..steppers.core.registry import INFO
    omega = omega_max(module, q[0], t[0], p)
    tau = "unknown (H singular at q0)" if omega is None else f"{h * omega:.3g}"
    stable = INFO[method].stable or "see the README steppers table"
    return (f"{module.NAME}, {method}: max |E - E0| = {err:.3g} is {err / scale:.3g} times the "
            f"energy scale {scale:.3g} (max T + range of V over the run; warning above "
            f"{ENERGY_FRACTION:g}) on a conservative model: h omega_max = {tau} at q0 "
            f"(K v = omega^2 H v, K = dg/dq), and {method} is {stable}; {advice}")


def energy_scale(module, q, t, energy, p, most=SCALE_ROWS):
    """max T + (max V - min V) over up to ``most`` saved rows, evenly spaced, the first and the
    last included; V = E(q, 0, t), T = E - V."""
    rows = spaced_rows(len(t), most)
    q = np.ascontiguousarray(q, dtype=np.float64)     # rows q[k] of the kernel's type
    zero = np.zeros(module.N_COORDS)
    energy_of = unchecked(module.energy)      # arrays made here, of the kernel's shapes
    # Python floats: on the few rows of the first estimate a numpy call costs more than the
    # arithmetic it does.
    V = [energy_of(q[k], zero, float(t[k]), p) for k in rows]
    E = (energy if len(t) <= most else energy[rows]).tolist()
    return max(ek - vk for ek, vk in zip(E, V)) + max(V) - min(V)


def spaced_rows(count, most):
    """Indices of up to ``most`` rows of ``count`` (>= 1), evenly spaced, the first and the last
    included: every row when count <= most, else floor(k (count - 1) / (most - 1))."""
    if count <= most:
        return range(count)
    return [k * (count - 1) // (most - 1) for k in range(most)]


def is_conservative(module, q0, v0, t0, p):
    """True when the model's energy E(q, v, t) is conserved by its flow (module docstring)."""
    if (getattr(module, "N_ELEMENTS", 0) or getattr(module, "N_CONSTRAINTS", 0)
            or getattr(module, "N_CONTACTS", 0)         # impacts and friction dissipate
            or getattr(module, "N_NONHOLONOMIC", 0)):   # rheonomic ones do work
        return False
    rng = np.random.default_rng(0)
    n = module.N_COORDS
    qs, vs = max(1.0, float(np.abs(q0).max())), max(1.0, float(np.abs(v0).max()))
    decided = False
    for _ in range(_SAMPLES):
        q = q0 + 0.5 * qs * rng.standard_normal(n)
        v = vs * rng.standard_normal(n)
        t = float(t0 + rng.standard_normal())
        power = _power_terms(module, q, v, t, p)
        if power is None:
            continue
        size = np.abs(power).sum()
        if size == 0.0:
            continue
        if abs(power.sum()) > POWER_RTOL * size:
            return False
        decided = True
    return decided


def _power_terms(module, q, v, t, p):
    """(dE/dq . v, dE/dv . a, dE/dt) (3,) at (q, v, t) by central differences, a from the
    generated forward dynamics; None where that fails or gives non-finite values."""
    n = module.N_COORDS
    H, a = np.empty((n, n)), np.empty(n)
    if module.forward_dynamics(q, v, t, p, H, a) != OK or not np.all(np.isfinite(a)):
        return None

    def energy(qq, vv, tt):
        return module.energy(np.ascontiguousarray(qq), np.ascontiguousarray(vv), tt, p)

    terms = []
    for dq, dv, dt in ((v, 0 * v, 0.0), (0 * v, a, 0.0), (0 * v, 0 * v, 1.0)):
        size = max(float(np.abs(dq).max()), float(np.abs(dv).max()), abs(dt))
        if size == 0.0:
            terms.append(0.0)
            continue
        eps = 1e-4 / size
        plus = energy(q + eps * dq, v + eps * dv, t + eps * dt)
        minus = energy(q - eps * dq, v - eps * dv, t - eps * dt)
        terms.append((plus - minus) / (2 * eps))
    terms = np.array(terms)
    return terms if np.all(np.isfinite(terms)) else None


def omega_max(module, q, t, p):
    """Largest sqrt(|lambda|) of K v = lambda H v at q (K = dg/dq by central differences of
    dynamics at qd = 0); None when H(q) is not positive definite or K is not finite."""
    n = module.N_COORDS
    q = np.ascontiguousarray(q, dtype=np.float64)
    zero, H, rhs = np.zeros(n), np.empty((n, n)), np.empty(n)
    K = np.empty((n, n))
    for j in range(n):
        d = 1e-6 * max(1.0, abs(q[j]))
        cols = []
        for sign in (1.0, -1.0):
            qq = q.copy()
            qq[j] += sign * d
            module.dynamics(qq, zero, float(t), p, H, rhs)
            cols.append(rhs.copy())
        K[:, j] = -(cols[0] - cols[1]) / (2 * d)          # rhs = -g(q) at qd = 0
    module.dynamics(q, zero, float(t), p, H, rhs)
    if not (np.all(np.isfinite(K)) and np.all(np.isfinite(H))):
        return None
    try:
        L = np.linalg.cholesky(0.5 * (H + H.T))
    except np.linalg.LinAlgError:
        return None
    A = np.linalg.solve(L, np.linalg.solve(L, 0.5 * (K + K.T)).T)     # L^-1 K L^-T
    return float(np.sqrt(np.abs(np.linalg.eigvalsh(0.5 * (A + A.T))).max()))
