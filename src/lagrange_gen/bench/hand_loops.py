"""Hand-written numba loops of the cart pendulum for `lagrange-gen bench steppers`: what a person
would write for this one model (its equations typed in by hand, 2 x 2 solves by Cramer's rule,
no generality, no checks), for explicit Euler, RK4, symplectic Euler and Verlet. The implicit
ones stop Newton by the library's rule (tolerance TOL) so that both do the same iterations.
Each returns the final state [x, theta, xd, thetad] (4,).
"""

from __future__ import annotations

import math

import numpy as np

from ..jit.cache import njit

TOL = 1e-12


# ---------------------------------------------------------------- hand-written, closed form
# Cart pendulum, p = (M, m, l, k, g): H = [[M + m, m l c], [m l c, m l^2]],
# rhs = (-k x + m l s thd^2, -m g l s), f = dT/dq - dV/dq = (-k x, -m g l s - m l s xd thd).

@njit(cache=True)
def _accel(x, th, xd, thd, p):
    M, m, l, k, g = p[0], p[1], p[2], p[3], p[4]
    c, s = math.cos(th), math.sin(th)
    h00, h01, h11 = M + m, m * l * c, m * l * l
    r0, r1 = -k * x + m * l * s * thd * thd, -m * g * l * s
    det = h00 * h11 - h01 * h01
    return (h11 * r0 - h01 * r1) / det, (h00 * r1 - h01 * r0) / det


@njit(cache=True)
def hand_explicit_euler(q0, v0, h, n, p):
    x, th, xd, thd = q0[0], q0[1], v0[0], v0[1]
    for _ in range(n):
        a0, a1 = _accel(x, th, xd, thd, p)
        x, th = x + h * xd, th + h * thd
        xd, thd = xd + h * a0, thd + h * a1
    return np.array([x, th, xd, thd])


@njit(cache=True)
def hand_rk4(q0, v0, h, n, p):
    x, th, xd, thd = q0[0], q0[1], v0[0], v0[1]
    for _ in range(n):
        a0, a1 = _accel(x, th, xd, thd, p)
        xd2, thd2 = xd + 0.5 * h * a0, thd + 0.5 * h * a1
        b0, b1 = _accel(x + 0.5 * h * xd, th + 0.5 * h * thd, xd2, thd2, p)
        xd3, thd3 = xd + 0.5 * h * b0, thd + 0.5 * h * b1
        c0, c1 = _accel(x + 0.5 * h * xd2, th + 0.5 * h * thd2, xd3, thd3, p)
        d0, d1 = _accel(x + h * xd3, th + h * thd3, xd + h * c0, thd + h * c1, p)
        xd4, thd4 = xd + h * c0, thd + h * c1
        x += h / 6 * (xd + 2 * xd2 + 2 * xd3 + xd4)
        th += h / 6 * (thd + 2 * thd2 + 2 * thd3 + thd4)
        xd += h / 6 * (a0 + 2 * b0 + 2 * c0 + d0)
        thd += h / 6 * (a1 + 2 * b1 + 2 * c1 + d1)
    return np.array([x, th, xd, thd])


@njit(cache=True)
def _converged(d0, d1, u0, u1, prev, tol):
    """The library's Newton stopping rule (steppers.core.newton.newton_converged) on 2-vectors."""
    size = tol * max(1.0, abs(u0), abs(u1))
    d = max(abs(d0), abs(d1))
    if d <= size:
        return True, d
    if prev > 0.0:
        theta = d / prev
        if theta < 1.0 and theta / (1.0 - theta) * d <= size:
            return True, d
    return False, d


@njit(cache=True)
def _kick(x, th, p0, p1, hk, u0, u1, p, tol):
    """Solve H(q) u = p + hk f(q, u) by Newton (2 x 2); returns (u0, u1, iterations)."""
    M, m, l, k, g = p[0], p[1], p[2], p[3], p[4]
    c, s = math.cos(th), math.sin(th)
    h00, h01, h11 = M + m, m * l * c, m * l * l
    prev = 0.0
    for it in range(1, 51):
        f0, f1 = -k * x, -m * g * l * s - m * l * s * u0 * u1
        r0 = h00 * u0 + h01 * u1 - p0 - hk * f0
        r1 = h01 * u0 + h11 * u1 - p1 - hk * f1
        a00, a01 = h00, h01
        a10, a11 = h01 + hk * m * l * s * u1, h11 + hk * m * l * s * u0
        det = a00 * a11 - a01 * a10
        d0, d1 = -(a11 * r0 - a01 * r1) / det, -(a00 * r1 - a10 * r0) / det
        u0, u1 = u0 + d0, u1 + d1
        done, prev = _converged(d0, d1, u0, u1, prev, tol)
        if done:
            return u0, u1, it
    return u0, u1, -1


@njit(cache=True)
def _drift(x, th, u0, u1, p0, p1, hd, p, tol):
    """Solve H(q + hd (u + w)) w = p for w by Newton; returns (w0, w1, x+, th+, iterations)."""
    M, m, l = p[0], p[1], p[2]
    w0, w1 = u0, u1
    prev = 0.0
    for it in range(1, 51):
        th_n = th + hd * (u1 + w1)
        c, s = math.cos(th_n), math.sin(th_n)
        h00, h01, h11 = M + m, m * l * c, m * l * l
        r0, r1 = h00 * w0 + h01 * w1 - p0, h01 * w0 + h11 * w1 - p1
        a00, a01 = h00, h01 - hd * m * l * s * w1
        a10, a11 = h01, h11 - hd * m * l * s * w0
        det = a00 * a11 - a01 * a10
        d0, d1 = -(a11 * r0 - a01 * r1) / det, -(a00 * r1 - a10 * r0) / det
        w0, w1 = w0 + d0, w1 + d1
        done, prev = _converged(d0, d1, w0, w1, prev, tol)
        if done:
            return w0, w1, x + hd * (u0 + w0), th + hd * (u1 + w1), it
    return w0, w1, x, th, -1


@njit(cache=True)
def _velocity(th, p0, p1, p):
    M, m, l = p[0], p[1], p[2]
    h00, h01, h11 = M + m, m * l * math.cos(th), m * l * l
    det = h00 * h11 - h01 * h01
    return (h11 * p0 - h01 * p1) / det, (h00 * p1 - h01 * p0) / det


@njit(cache=True)
def hand_symplectic_euler(q0, v0, h, n, p, tol):
    M, m, l = p[0], p[1], p[2]
    x, th, xd, thd = q0[0], q0[1], v0[0], v0[1]
    c = math.cos(th)
    p0, p1 = (M + m) * xd + m * l * c * thd, m * l * c * xd + m * l * l * thd
    for _ in range(n):
        u0, u1, it = _kick(x, th, p0, p1, h, xd, thd, p, tol)
        if it < 0:
            break
        c = math.cos(th)
        p0, p1 = (M + m) * u0 + m * l * c * u1, m * l * c * u0 + m * l * l * u1
        x, th = x + h * u0, th + h * u1
        xd, thd = _velocity(th, p0, p1, p)
    return np.array([x, th, xd, thd])


@njit(cache=True)
def hand_verlet(q0, v0, h, n, p, tol):
    M, m, l, k, g = p[0], p[1], p[2], p[3], p[4]
    x, th, xd, thd = q0[0], q0[1], v0[0], v0[1]
    c = math.cos(th)
    p0, p1 = (M + m) * xd + m * l * c * thd, m * l * c * xd + m * l * l * thd
    for _ in range(n):
        u0, u1, it = _kick(x, th, p0, p1, 0.5 * h, xd, thd, p, tol)
        if it < 0:
            break
        c = math.cos(th)
        ph0, ph1 = (M + m) * u0 + m * l * c * u1, m * l * c * u0 + m * l * l * u1
        w0, w1, x, th, it = _drift(x, th, u0, u1, ph0, ph1, 0.5 * h, p, tol)
        if it < 0:
            break
        s = math.sin(th)
        p0 = ph0 + 0.5 * h * (-k * x)
        p1 = ph1 + 0.5 * h * (-m * g * l * s - m * l * s * w0 * w1)
        xd, thd = _velocity(th, p0, p1, p)
    return np.array([x, th, xd, thd])


HAND_CLOSED_FORM = {"explicit_euler": hand_explicit_euler, "rk4": hand_rk4,
                    "symplectic_euler": hand_symplectic_euler, "verlet": hand_verlet}
NEWTON_HAND = ("symplectic_euler", "verlet")
