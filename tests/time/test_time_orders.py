"""Every fixed-step method on a rheonomic model: fitted orders against scipy DOP853 (rtol 1e-12)
references, one on the generated right-hand side and one on a right-hand side derived by hand.

Unconstrained: tests/time/models/breathing_frame.py, a particle in a turning (phi(t)) and
breathing (s(t)) frame: H(t) = m s^2 I, Coriolis (T1), centrifugal (T0), V(q, t). By hand, from
r = s R(phi) q and m s (u' + phi' J u) = -dV/dq with u = s' q + s q' + s phi' J q:

    s q'' = -dV/dq / (m s) - s'' q - 2 s' q' - (2 s' phi' + s phi'') J q - 2 s phi' J q' + s phi'^2 q

Constrained: models/slider_crank.py, crank angle w t prescribed, so both loop constraints are
rheonomic. The slider follows x(t) = r cos(w t) + sqrt(L^2 - r^2 sin(w t)^2), and the spring
mass at x + y obeys m3 (x'' + y'') = -k y - c y': a scalar ODE for y, the independent reference.
"""

import math

import numpy as np
import pytest
import sympy as sp

from lagrange_gen import simulate
from lagrange_gen.steppers.core.registry import CONSTRAINED_METHODS, INFO, METHODS, NONSMOOTH_METHODS
from time_util import dop853, generated_rhs

T_END = 1.0
STEPS = {1: (256, 512, 1024, 2048), 2: (32, 64, 128, 256), 4: (16, 32, 64, 128), 6: (8, 12, 16, 24)}
FIXED = [m for m in METHODS if not INFO[m].adaptive and m not in NONSMOOTH_METHODS
         and not INFO[m].contacts and not INFO[m].nonholonomic]
UNCONSTRAINED = [m for m in FIXED if m not in CONSTRAINED_METHODS]
PB = dict(m=1.0, k=4.0, F=0.5, w=1.5, nu=2.0, e=0.3)
Q0, V0 = np.array([0.4, -0.2]), np.array([0.1, 0.3])


def breathing_hand_rhs(t, y):
    m, k, F, w, nu, e = PB.values()
    q, v = y[:2], y[2:]
    s, ds, dds = 1 + e * math.sin(nu * t) / 2, e * nu * math.cos(nu * t) / 2, -e * nu**2 * math.sin(nu * t) / 2
    dphi, ddphi = w + e * nu * math.cos(nu * t), -e * nu**2 * math.sin(nu * t)
    J = np.array([[0.0, -1.0], [1.0, 0.0]])
    gradV = np.array([k * q[0] + F * math.cos(nu * t), 2 * k * q[1]])
    a = (-gradV / (m * s) - dds * q - 2 * ds * v - (2 * ds * dphi + s * ddphi) * (J @ q)
         - 2 * s * dphi * (J @ v) + s * dphi**2 * q) / s
    return np.concatenate((v, a))


@pytest.fixture(scope="module")
def breathing(time_module):
    return time_module("breathing_frame")


@pytest.fixture(scope="module")
def breathing_reference(breathing):
    p = np.array(list(PB.values()))
    y0 = np.concatenate((Q0, V0))
    hand = dop853(breathing_hand_rhs, y0, T_END)
    ours = dop853(generated_rhs(breathing, p), y0, T_END)
    np.testing.assert_allclose(ours, hand, rtol=0, atol=1e-10)   # the generated rhs is right
    return hand


def fit(step_counts, errors):
    return float(np.polyfit(np.log(1.0 / np.asarray(step_counts)), np.log(errors), 1)[0])


@pytest.mark.parametrize("method", UNCONSTRAINED)
def test_rheonomic_orders(breathing, breathing_reference, method):
    order, errors = INFO[method].order, []
    for n in STEPS[INFO[method].order]:
        tr = simulate(breathing, method, Q0, V0, t_end=T_END, h=T_END / n, params=PB, save_every=n)
        errors.append(np.abs(np.concatenate((tr.q[-1], tr.v[-1])) - breathing_reference).max())
    slope = fit(STEPS[order], errors)
    print(method, f"order {slope:.2f}", errors)
    assert abs(slope - order) < 0.3, (method, slope, errors)


PS = dict(r=0.3, L=1.0, w=6.0, m2=1.0, m3=0.5, k=40.0, c=0.8)


def slider_closed_form():
    """x(t), x''(t) of the slider as numpy functions (sympy differentiates the closed form)."""
    tt = sp.Symbol("t")
    x = PS["r"] * sp.cos(PS["w"] * tt) + sp.sqrt(PS["L"]**2 - PS["r"]**2 * sp.sin(PS["w"] * tt)**2)
    return sp.lambdify(tt, x), sp.lambdify(tt, x.diff(tt)), sp.lambdify(tt, x.diff(tt, 2))


@pytest.fixture(scope="module")
def slider(time_module):
    return time_module("slider_crank")


def slider_start(t0=0.0, y0=0.1, vy0=0.0):
    """A consistent state at t0: psi, x from the closed-form kinematics."""
    x, dx, _ = slider_closed_form()
    r, L, w = PS["r"], PS["L"], PS["w"]
    psi = math.asin(r * math.sin(w * t0) / L)
    dpsi = r * w * math.cos(w * t0) / (L * math.cos(psi))
    return np.array([psi, x(t0), y0]), np.array([dpsi, dx(t0), vy0])


@pytest.fixture(scope="module")
def slider_reference():
    _, _, ddx = slider_closed_form()
    k, c, m3 = PS["k"], PS["c"], PS["m3"]
    return dop853(lambda t, z: [z[1], -(k * z[0] + c * z[1]) / m3 - ddx(t)], [0.1, 0.0], T_END)


@pytest.mark.parametrize("method", CONSTRAINED_METHODS)
def test_rheonomic_constraint_orders(slider, slider_reference, method):
    order = INFO[method].order
    q0, v0 = slider_start()
    x, dx, _ = slider_closed_form()
    errors = []
    for n in STEPS[order]:
        tr = simulate(slider, method, q0, v0, t_end=T_END, h=T_END / n, params=PS, save_every=n)
        errors.append(max(abs(tr.q[-1, 2] - slider_reference[0]), abs(tr.v[-1, 2] - slider_reference[1])))
        # Position constraints hold at every step for the projected methods (x exact to Newton).
        if INFO[method].constraint_drift == "none":
            assert abs(tr.q[-1, 1] - x(tr.t[-1])) < 1e-9
            assert abs(tr.v[-1, 1] - dx(tr.t[-1])) < 1e-8      # J v + dPhi/dt = 0
    slope = fit(STEPS[order], errors)
    print(method, f"order {slope:.2f}", errors)
    assert abs(slope - order) < 0.3, (method, slope, errors)


def ring_hand_rhs(t, z):
    """The bead's angle on the ring, by hand: T = m (s'^2 + s^2 (th' + phi')^2) / 2, so
    m s^2 (th'' + phi'') + 2 m s s' (th' + phi') = -dV/dth."""
    m, k, F, w, nu, e = PB.values()
    th, dth = z
    s, ds = 1 + e * math.sin(nu * t) / 2, e * nu * math.cos(nu * t) / 2
    dphi, ddphi = w + e * nu * math.cos(nu * t), -e * nu**2 * math.sin(nu * t)
    dV = k * math.sin(th) * math.cos(th) - F * math.cos(nu * t) * math.sin(th)
    return [dth, -dV / (m * s * s) - ddphi - 2 * ds / s * (dth + dphi)]


@pytest.fixture(scope="module")
def ring(time_module):
    return time_module("breathing_ring")


@pytest.mark.parametrize("method", CONSTRAINED_METHODS)
def test_gyroscopic_constrained_orders(ring, method):
    """Constrained methods with a gyroscopic T1, H(t) and V(q, t): the angle and its rate."""
    th0, dth0 = 0.7, 0.4
    ref = dop853(ring_hand_rhs, [th0, dth0], T_END)
    q0, v0 = [math.cos(th0), math.sin(th0)], [-math.sin(th0) * dth0, math.cos(th0) * dth0]
    order, errors = INFO[method].order, []
    for n in STEPS[order]:
        tr = simulate(ring, method, q0, v0, t_end=T_END, h=T_END / n, params=PB, save_every=n)
        (x, y), (dx, dy) = tr.q[-1], tr.v[-1]
        errors.append(max(abs(math.atan2(y, x) - ref[0]), abs(x * dy - y * dx - ref[1])))
    slope = fit(STEPS[order], errors)
    print(method, f"order {slope:.2f}", errors)
    assert abs(slope - order) < 0.3, (method, slope, errors)
