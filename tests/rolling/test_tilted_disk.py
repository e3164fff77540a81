"""models/tilted_disk.py (a disk rolling on a plane, free to tilt) against Routh's rolling coin.

Linearized about upright straight rolling at the spin rate omega (lagrange_gen.
linearize_nonholonomic, independent speeds psi', theta', phi'), the tilt and heading obey
(I_diam + m R^2) theta'' = (m g R - I_axle (I_axle + m R^2) omega^2 / I_diam) theta (the
gyroscopic coupling I_axle omega between tilt and heading and the wheel's rolling eliminated),
so the nonzero eigenvalues are +-sqrt(s) with s = (m g R - I_axle (I_axle + m R^2) omega^2 /
I_diam) / (I_diam + m R^2): the coin is stable above omega_c^2 = m g R I_diam / (I_axle (I_axle
+ m R^2)) = g / (3 R) for a uniform disk. Round-off only in the linearization (1e-10).

The nonlinear model then does what the linearization says (nonholonomic_midpoint): started
with a small tilt above omega_c it stays near upright, below it falls over; the energy of this
conservative system stays within C h^2 and the rolling constraint holds to round-off.
"""

import math

import numpy as np
import pytest
from scipy.optimize import brentq

import lagrange_gen as lg
from lagrange_gen.run.simulate import simulate

M, R, I_DIAM, I_AXLE, G = 1.0, 0.5, 0.0625, 0.125, 9.81
SPEEDS = ("psi", "theta", "phi")


@pytest.fixture(scope="module")
def disk(generated):
    return generated("tilted_disk")


def rolling_straight(omega):
    return np.zeros(5), np.array([R * omega, 0.0, 0.0, 0.0, omega])


def nonzero_eigenvalues(disk, omega):
    lin = lg.linearize_nonholonomic(disk, *rolling_straight(omega), speeds=SPEEDS)
    eig = np.linalg.eigvals(lin.A)
    return np.sort_complex(eig[np.abs(eig) > 1e-9])


@pytest.mark.parametrize("omega", [0.0, 2.0, 5.0, 12.0])
def test_upright_rolling_eigenvalues_are_rouths(disk, omega):
    s = (M * G * R - I_AXLE * (I_AXLE + M * R**2) * omega**2 / I_DIAM) / (I_DIAM + M * R**2)
    root = math.sqrt(abs(s))
    expected = [-root, root] if s > 0 else [-1j * root, 1j * root]
    np.testing.assert_allclose(nonzero_eigenvalues(disk, omega), np.sort_complex(expected),
                               rtol=0, atol=1e-10)


def test_critical_spin_is_sqrt_of_g_over_3R(disk):
    def s(omega):             # lambda^2 of the tilt mode: the product of the pair, negated
        eig = nonzero_eigenvalues(disk, omega)
        return -float(np.real(eig[0] * eig[1]))

    omega_c = brentq(s, 1.0, 5.0, xtol=1e-13)
    assert abs(omega_c - math.sqrt(G / (3 * R))) < 1e-9
    assert s(0.9 * omega_c) > 0 > s(1.1 * omega_c)


def max_tilt_linear(omega, theta0):
    """Linear theory from theta(0) = theta0, theta'(0) = psi'(0) = 0: the heading equation
    I_diam psi'' = I_axle omega theta' gives psi' = I_axle omega (theta - theta0) / I_diam, so
    the tilt oscillates about theta_e = k theta0 / (k - m g R), k = (I_axle + m R^2) I_axle
    omega^2 / I_diam, between theta0 and 2 theta_e - theta0 (above omega_c, k > m g R)."""
    k = (I_AXLE + M * R**2) * I_AXLE * omega**2 / I_DIAM
    return theta0 * (2 * k / (k - M * G * R) - 1)


@pytest.mark.parametrize("omega", [2.0, 4.0, 6.0])
def test_the_nonlinear_coin_stands_or_falls(disk, omega):
    """Above omega_c (2.56 rad/s) the tilt swings as linear theory says (2% covers the
    nonlinear terms, O(theta^2) = 1e-3 relative, and the O(h^2) error); below it the coin falls."""
    theta0 = 0.02
    q0, v0 = rolling_straight(omega)
    q0[3] = theta0
    traj = simulate(disk, "nonholonomic_midpoint", q0, v0, t_end=3.0, h=0.005)
    tilt = np.abs(traj.q[:, 3]).max()
    if omega < math.sqrt(G / (3 * R)):
        assert tilt > 10 * theta0
    else:
        assert abs(tilt / max_tilt_linear(omega, theta0) - 1) < 0.02
        assert np.abs(traj.energy - traj.energy[0]).max() < 1e-7
    assert traj.saved["velocity_constraint_error"].max() < 1e-12
