"""Spherical pendulum (models/spherical_pendulum.py) on a conical orbit, through every
unconstrained stepper.

The model: q1 = theta is the polar angle from the UPWARD vertical, q2 = phi the azimuth,
T = m l^2 (theta'^2 + sin(theta)^2 phi'^2) / 2, V = m g l cos(theta).
Lagrange's equation for theta:
    m l^2 theta'' = m l^2 sin(theta) cos(theta) phi'^2 + m g l sin(theta).
A steady conical motion theta = theta0, theta' = 0 needs theta'' = 0, i.e. (sin(theta0) != 0)
    phi'^2 = -g / (l cos(theta0)),
real for a bob below the pivot (cos(theta0) < 0); with alpha = pi - theta0, the angle from the
downward vertical, this is the textbook phi'^2 = g / (l cos(alpha)). phi is cyclic, so
    p_phi = m l^2 sin(theta0)^2 phi' is conserved, and phi' stays constant,
    E = m l^2 sin(theta0)^2 phi'^2 / 2 + m g l cos(theta0), one revolution takes 2 pi / phi'.

On this orbit the vector field is the constant (theta', phi', theta'', phi'') = (0, Omega, 0, 0):
every consistent one-step method integrates it exactly, so the state must follow the closed form
to roundoff (roundoff_bound: one rounding per step of a quantity of the given size). A kernel
with a wrong term gives theta'' != 0 there and fails at once.
"""

import math

import numpy as np
import pytest

from zoo_util import (UNCONSTRAINED_METHODS, assert_model_allows_every_method, roundoff_bound,
                      run)

PARAMS = {"m": 1.5, "l": 0.8, "g": 9.81}
ALPHA = 0.6                                  # angle of the cone from the downward vertical
THETA0 = math.pi - ALPHA
OMEGA = math.sqrt(-PARAMS["g"] / (PARAMS["l"] * math.cos(THETA0)))
REVOLUTION = 2 * math.pi / OMEGA
N_STEPS = 1000
M_L2 = PARAMS["m"] * PARAMS["l"]**2
P_PHI = M_L2 * math.sin(THETA0)**2 * OMEGA
KINETIC = M_L2 * math.sin(THETA0)**2 * OMEGA**2 / 2
POTENTIAL = PARAMS["m"] * PARAMS["g"] * PARAMS["l"] * math.cos(THETA0)


def test_conical_rate_is_the_textbook_one():
    """phi'^2 = g / (l cos(alpha)) with alpha from the downward vertical."""
    assert OMEGA**2 == pytest.approx(PARAMS["g"] / (PARAMS["l"] * math.cos(ALPHA)), rel=1e-15)


@pytest.fixture(scope="module")
def pendulum(generated):
    mod = generated("spherical_pendulum")
    assert_model_allows_every_method(mod)
    return mod


@pytest.mark.parametrize("method", UNCONSTRAINED_METHODS)
def test_conical_orbit_is_kept(pendulum, method):
    """theta = theta0 and phi' = Omega over one revolution, phi = Omega t, the start is reached
    again after 2 pi / Omega, and p_phi and E keep their closed-form values."""
    traj = run(pendulum, method, [THETA0, 0.0], [0.0, OMEGA], REVOLUTION, N_STEPS, PARAMS)
    theta, phi = traj.q[:, 0], traj.q[:, 1]
    assert np.abs(theta - THETA0).max() <= roundoff_bound(THETA0, N_STEPS)
    assert np.abs(traj.v[:, 0]).max() <= roundoff_bound(OMEGA, N_STEPS)
    assert np.abs(traj.v[:, 1] - OMEGA).max() <= roundoff_bound(OMEGA, N_STEPS)
    assert np.abs(phi - OMEGA * traj.t).max() <= roundoff_bound(2 * math.pi, N_STEPS)
    assert abs(phi[-1] - 2 * math.pi) <= roundoff_bound(2 * math.pi, N_STEPS)
    p_phi = M_L2 * np.sin(theta)**2 * traj.v[:, 1]
    assert np.abs(p_phi - P_PHI).max() <= roundoff_bound(P_PHI, N_STEPS)
    energy_scale = KINETIC + abs(POTENTIAL)
    assert np.abs(traj.energy - (KINETIC + POTENTIAL)).max() <= roundoff_bound(energy_scale,
                                                                                N_STEPS)
