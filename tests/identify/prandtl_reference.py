"""Exact reference simulator for the generalized Prandtl model with linear hardening (test helper).

Model (one degree of freedom; n Saint-Venant elements in parallel with a spring k0, a dashpot c)::

    m x'' + c x' + k0 x + sum_i k_i u_i = F(t),      u_i' + dpsi_[-eta_i, eta_i](u_i) ∋ x'.

Implicit Euler with step h: v_{n+1} = (x_{n+1} - x_n) / h, a_{n+1} = (v_{n+1} - v_n) / h, and the
element update is the exact return map (the implicit Euler step of the inclusion)::

    u_{i,n+1} = clamp(u_{i,n} + x_{n+1} - x_n, -eta_i, eta_i).

Substituting gives one scalar equation for the increment d = x_{n+1} - x_n::

    g(d) = (m/h^2 + c/h + k0) d + sum_i k_i clamp(u_i + d, -eta_i, eta_i) + const = F_{n+1},

g is continuous, piecewise linear and strictly increasing (slope >= m/h^2 > 0), so the root is
unique and found exactly: evaluate g at its kinks d = +-eta_i - u_i, bracket the root, and solve the
linear piece that holds it. No Newton tolerance is involved; the discrete identity
F_{n+1} - m a_{n+1} - c v_{n+1} = k0 x_{n+1} + sum k_i u_{i,n+1} holds to round-off, which is
what makes the loading branches in the (x, F - m x'' - c x') plane exactly piecewise linear.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass
class PrandtlRun:
    """Sampled trajectory; every array has shape (n_steps + 1,) except u: (n_steps + 1, n)."""

    t: np.ndarray
    x: np.ndarray
    v: np.ndarray
    a: np.ndarray
    u: np.ndarray
    force: np.ndarray

    @property
    def f_minus_ma(self):
        """F - m x'' with m = 1 is what the tests hand to the identification (shape (N,))."""
        return self.force - self.a


def _clamp(value, bound):
    return min(max(value, -bound), bound)


def _solve_increment(u, k, eta, stiff, rhs):
    """Root d of stiff * d + sum k_i clamp(u_i + d, -eta_i, eta_i) = rhs (increasing in d)."""
    def g(d):
        return stiff * d + sum(ki * _clamp(ui + d, ei) for ui, ki, ei in zip(u, k, eta))

    kinks = sorted({s * ei - ui for ui, ei in zip(u, eta) for s in (-1.0, 1.0)})
    lo, hi = -math.inf, math.inf
    for d in kinks:
        if g(d) <= rhs:
            lo = d
        else:
            hi = d
            break
    # On [lo, hi] g is affine: its slope is stiff plus the k_i of elements not saturated there.
    mid = lo + 1.0 if hi == math.inf else (hi - 1.0 if lo == -math.inf else 0.5 * (lo + hi))
    slope = stiff + sum(ki for ui, ki, ei in zip(u, k, eta) if abs(ui + mid) < ei)
    anchor = lo if lo != -math.inf else hi
    return anchor + (rhs - g(anchor)) / slope


def simulate_prandtl(m, c, k0, k, eta, force, h, t_end, x0=0.0, v0=0.0, u0=None):
    """Implicit Euler run of the model above; force is a callable F(t). Returns a PrandtlRun."""
    k, eta = list(map(float, k)), list(map(float, eta))
    u = [0.0] * len(k) if u0 is None else list(map(float, u0))
    n_steps = int(round(t_end / h))
    t = h * np.arange(n_steps + 1)
    xs, vs, as_, us = [x0], [v0], [0.0], [list(u)]
    x, v = x0, v0
    stiff = m / h**2 + c / h + k0
    for n in range(n_steps):
        # Collect the terms of the step equation that do not depend on d (see the module docstring).
        rhs = force(t[n + 1]) + m * v / h - k0 * x
        d = _solve_increment(u, k, eta, stiff, rhs)
        u = [_clamp(ui + d, ei) for ui, ei in zip(u, eta)]
        v_new = d / h
        as_.append((v_new - v) / h)
        x, v = x + d, v_new
        xs.append(x), vs.append(v), us.append(list(u))
    as_[0] = (force(0.0) - c * v0 - k0 * x0 - sum(ki * ui for ki, ui in zip(k, us[0]))) / m
    force_samples = np.array([force(ti) for ti in t])
    return PrandtlRun(t, np.array(xs), np.array(vs), np.array(as_), np.array(us), force_samples)
