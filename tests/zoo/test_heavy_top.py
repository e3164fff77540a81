"""Heavy symmetric top in Euler angles (models/heavy_top.py) through every unconstrained stepper.

L = I1/2 (theta'^2 + phi'^2 sin^2) + I3/2 w3^2 - m g l cos(theta), w3 = psi' + phi' cos(theta)
(theta from the upward vertical; sin, cos of theta). phi and psi are cyclic:
    p_psi = dL/dpsi' = I3 w3,   p_phi = dL/dphi' = I1 phi' sin^2 + I3 w3 cos   (conserved),
    E = I1/2 (theta'^2 + phi'^2 sin^2) + I3/2 w3^2 + m g l cos(theta).
Lagrange's equation for theta (d(I3 w3^2 / 2)/dtheta = -I3 w3 phi' sin):
    I1 theta'' = I1 phi'^2 sin cos - I3 w3 phi' sin + m g l sin.

Steady precession (theta = theta0, theta' = 0) needs theta'' = 0, i.e. with sin(theta0) != 0
    I1 cos(theta0) phi'^2 - I3 w3 phi' + m g l = 0,
    phi' = (I3 w3 -+ sqrt(I3^2 w3^2 - 4 I1 m g l cos(theta0))) / (2 I1 cos(theta0)),
slow (-) and fast (+) precession, psi' = w3 - phi' cos(theta0). All velocities are then constant:
the vector field is constant along the motion and every one-step method follows it to roundoff.

Nutation from rest in phi (theta' = phi' = 0, spin w3): with u = cos(theta), a = I3 w3 / I1 and
beta = 2 m g l / I1, the invariants give u'^2 = (u0 - u) (beta (1 - u^2) - a^2 (u0 - u)), so
theta oscillates between theta0 and theta1 = acos(u1), u1 the root below u0 of
    beta u^2 - a^2 u + a^2 u0 - beta = 0,
    u1 = (a^2 - sqrt(a^4 - 4 beta (a^2 u0 - beta))) / (2 beta).
"""

import math

import numpy as np
import pytest

from zoo_util import (SYMPLECTIC_METHODS, UNCONSTRAINED_METHODS, assert_model_allows_every_method,
                      assert_orders, order, roundoff_bound, run)

PARAMS = {"I1": 1.2, "I3": 0.5, "m": 1.1, "g": 9.81, "l": 0.45}
MGL = PARAMS["m"] * PARAMS["g"] * PARAMS["l"]
THETA0, SPIN = 0.5, 20.0                  # SPIN = w3
STEADY_STEPS, STEADY_T = 1000, 1.0


def invariants(q, v):
    """(E, p_phi, p_psi), each (S,), from the closed forms above."""
    I1, I3 = PARAMS["I1"], PARAMS["I3"]
    theta, theta_d, phi_d, psi_d = q[:, 0], v[:, 0], v[:, 1], v[:, 2]
    sin, cos = np.sin(theta), np.cos(theta)
    w3 = psi_d + phi_d * cos
    energy = I1 / 2 * (theta_d**2 + phi_d**2 * sin**2) + I3 / 2 * w3**2 + MGL * cos
    return energy, I1 * phi_d * sin**2 + I3 * w3 * cos, I3 * w3


def invariant_scales(v0):
    """Sums of the absolute values of the terms of (E, p_phi, p_psi) at theta0, velocities v0:
    the size a rounding of each is relative to."""
    I1, I3 = PARAMS["I1"], PARAMS["I3"]
    sin, cos = math.sin(THETA0), math.cos(THETA0)
    w3 = abs(v0[2]) + abs(v0[1] * cos)
    return (I1 / 2 * (v0[0]**2 + (v0[1] * sin)**2) + I3 / 2 * w3**2 + MGL,
            I1 * abs(v0[1]) * sin**2 + I3 * w3 * abs(cos), I3 * w3)


def precession_rate(sign):
    I1, I3, cos = PARAMS["I1"], PARAMS["I3"], math.cos(THETA0)
    return (I3 * SPIN + sign * math.sqrt((I3 * SPIN)**2 - 4 * I1 * MGL * cos)) / (2 * I1 * cos)


@pytest.fixture(scope="module")
def top(generated):
    mod = generated("heavy_top")
    assert_model_allows_every_method(mod)
    return mod


@pytest.mark.parametrize("sign", [-1, 1], ids=["slow", "fast"])
@pytest.mark.parametrize("method", UNCONSTRAINED_METHODS)
def test_steady_precession_is_kept(top, method, sign):
    """theta stays theta0, the velocities stay constant, phi and psi grow linearly, and E,
    p_phi, p_psi keep their values, each to roundoff."""
    phi_d = precession_rate(sign)
    v0 = np.array([0.0, phi_d, SPIN - phi_d * math.cos(THETA0)])
    traj = run(top, method, [THETA0, 0.0, 0.0], v0, STEADY_T, STEADY_STEPS, PARAMS)
    n, speed = STEADY_STEPS, np.abs(v0).max()
    assert np.abs(traj.q[:, 0] - THETA0).max() <= roundoff_bound(THETA0, n)
    assert np.abs(traj.v - v0).max() <= roundoff_bound(speed, n)
    angles = np.outer(traj.t, v0[1:])
    assert np.abs(traj.q[:, 1:] - angles).max() <= roundoff_bound(speed * STEADY_T, n)
    start = invariants(traj.q[:1], traj.v[:1])
    for name, values, exact, scale in zip(("E", "p_phi", "p_psi"), invariants(traj.q, traj.v),
                                          start, invariant_scales(v0)):
        assert np.abs(values - exact).max() <= roundoff_bound(scale, n), (name, method)


def test_steady_precession_rate_cancels_the_theta_acceleration(top):
    """Both rates make the generated theta'' vanish (against the hand-derived quadratic)."""
    for sign in (-1, 1):
        phi_d = precession_rate(sign)
        v = [0.0, phi_d, SPIN - phi_d * math.cos(THETA0)]
        qdd = top.accelerations([THETA0, 0.3, 0.2], v, params=PARAMS)
        # The terms of I1 theta'' cancel: a few roundings of the largest of them.
        terms = PARAMS["I1"] * phi_d**2 + PARAMS["I3"] * SPIN * abs(phi_d) + MGL
        print(f"precession {sign:+d}: max |qdd| = {np.abs(qdd).max():.2e}")
        assert np.abs(qdd).max() <= roundoff_bound(terms / PARAMS["I1"], 10)


# Nutation: one second is about 1.2 nutation periods (w = sqrt(a^2 - 2 beta u0) = 7.4 rad/s).
NUTATION_T = 1.0
STEPS = {1: (800, 1600, 3200), 2: (200, 400, 800), 4: (100, 200, 400), 6: (50, 100, 200)}


def lowest_point():
    """theta1 of the nutation from rest in phi (the root u1 in the module docstring)."""
    a = PARAMS["I3"] * SPIN / PARAMS["I1"]
    beta, u0 = 2 * MGL / PARAMS["I1"], math.cos(THETA0)
    u1 = (a**2 - math.sqrt(a**4 - 4 * beta * (a**2 * u0 - beta))) / (2 * beta)
    return math.acos(u1), a


def nutation_errors(mod, method, n_steps):
    """(trajectory, {invariant: max |change|}) over NUTATION_T with n_steps steps."""
    traj = run(mod, method, [THETA0, 0.0, 0.0], [0.0, 0.0, SPIN], NUTATION_T, n_steps, PARAMS)
    values = invariants(traj.q, traj.v)
    return traj, {name: np.abs(x - x[0]).max() for name, x in zip(("E", "p_phi", "p_psi"), values)}


@pytest.mark.parametrize("method", UNCONSTRAINED_METHODS)
def test_nutation_invariants_and_turning_points(top, method):
    """E has the method's order; p_phi and p_psi are exact for the symplectic methods (discrete
    Noether, cyclic angles) and of the method's order otherwise. theta stays between theta0 and
    theta1 at the finest step: the extremes of the saved theta miss them by at most the
    sampling error A (a h)^2 / 16 plus the method's error, bounded by 3 A (a h)^p (measured
    constant: 0.7, explicit Euler). A = theta1 - theta0; near u0, x = u0 - u obeys
    x'^2 = c x - d x^2 + O(x^3) with d = a^2 - 2 beta u0, so theta nutates about as
    A/2 cos(w t) with w = sqrt(d) < a, and a sample within h/2 of an extreme misses it by at
    most A/2 (1 - cos(w h / 2)) <= A (a h)^2 / 16."""
    steps = STEPS[order(method)]
    runs = [nutation_errors(top, method, n) for n in steps]
    errors = {name: [row[name] for _, row in runs] for name in runs[0][1]}
    if method in SYMPLECTIC_METHODS:
        scales = dict(zip(("E", "p_phi", "p_psi"), invariant_scales([0.0, 0.0, SPIN])))
        for name in ("p_phi", "p_psi"):
            for n, err in zip(steps, errors.pop(name)):
                assert err <= roundoff_bound(scales[name], n), (method, name, n, err)
    assert_orders(method, steps, errors, {"E": order(method), "p_phi": order(method),
                                          "p_psi": order(method)})
    traj, _ = runs[-1]
    theta1, a = lowest_point()
    amplitude, ah = theta1 - THETA0, a * traj.h
    tol = amplitude * (ah**2 / 16 + 3 * ah**order(method))
    print(f"{method}: turning points off by {traj.q[:, 0].max() - theta1:.2e}, "
          f"{traj.q[:, 0].min() - THETA0:.2e} (tolerance {tol:.2e})")
    assert abs(traj.q[:, 0].max() - theta1) <= tol, (method, traj.q[:, 0].max(), theta1, tol)
    assert abs(traj.q[:, 0].min() - THETA0) <= tol, (method, traj.q[:, 0].min(), tol)
