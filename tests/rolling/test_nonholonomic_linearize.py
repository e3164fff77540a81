"""lg.linearize / lg.linearize_nonholonomic on models with velocity constraints, against closed
forms derived by hand from the models' docstrings (not through derive/).

Chaplygin sleigh (mass m, inertia I, knife edge a behind the centre of mass) moving straight
along its axis at speed U, independent speeds (x', theta'): y' = tan(theta) x' + a theta' /
cos(theta), so dy' = U dtheta + a dw; the forward speed's equation u' = a w^2 has no linear part
and w' = -m a u w / (I + m a^2) gives dw' = -k dw with k = m a U / (I + m a^2): stable forwards
(U > 0), unstable backwards. The partial velocities are (1, 0, 0) and (0, a, 1), so the mass
is diag(m, m a^2 + I) and the damping's (w, w) entry m a U.

Vertical rolling disk on its circle (spin omega, turning rate Omega, heading phi), independent
speeds (phi', theta'): x' = R cos(phi) theta', y' = R sin(phi) theta', so dx' = -R omega
sin(phi) dphi + R cos(phi) dtheta' (the dependent speeds' change with the configuration, W in
linear/nonholonomic.py), and the speeds' equations phi'' = theta'' = 0 have no linear part.

Round-off only: exact derivative kernels, so 1e-12.
"""

import math

import numpy as np
import pytest

import lagrange_gen as lg

SLEIGH_M, SLEIGH_I, SLEIGH_A = 1.0, 0.2, 0.5


@pytest.mark.parametrize("U", [2.0, -1.5])
def test_sleigh_straight_motion(generated, U):
    sleigh = generated("chaplygin_sleigh")
    lin = lg.linearize_nonholonomic(sleigh, [0.0, 0.0, 0.0], [U, 0.0, 0.0], speeds=("x", "theta"))
    assert lin.coordinates == ("x", "y", "theta") and lin.speeds == ("x_dot", "theta_dot")
    k = SLEIGH_M * SLEIGH_A * U / (SLEIGH_I + SLEIGH_M * SLEIGH_A**2)
    #                 x    y    theta  x'   w
    expected = np.array([[0, 0, 0, 1, 0],           # x' = u_x
                         [0, 0, U, 0, SLEIGH_A],    # dy' = U dtheta + a dw
                         [0, 0, 0, 0, 1],           # theta' = w
                         [0, 0, 0, 0, 0],           # u' = a w^2
                         [0, 0, 0, 0, -k]])         # dw' = -k dw
    np.testing.assert_allclose(lin.A, expected, rtol=0, atol=1e-12)
    np.testing.assert_allclose(lin.mass, np.diag([SLEIGH_M, SLEIGH_M * SLEIGH_A**2 + SLEIGH_I]),
                               rtol=0, atol=1e-12)
    np.testing.assert_allclose(lin.damping, [[0, 0], [0, SLEIGH_M * SLEIGH_A * U]], rtol=0,
                               atol=1e-12)
    np.testing.assert_allclose(lin.stiffness, np.zeros((2, 3)), rtol=0, atol=1e-12)
    # lg.linearize gives the same (z, u) system
    np.testing.assert_allclose(lg.linearize(sleigh, [0, 0, 0], [U, 0, 0], speeds=("x", "theta")).A,
                               expected, rtol=0, atol=1e-12)


def test_disk_on_its_circle(generated):
    disk = generated("rolling_disk")
    R, omega, Omega, phi = 0.5, 4.0, 1.5, 0.3
    q = [0.1, -0.2, phi, 0.7]
    qd = [R * omega * math.cos(phi), R * omega * math.sin(phi), Omega, omega]
    lin = lg.linearize_nonholonomic(disk, q, qd, speeds=("phi", "theta"))
    #                 x  y  phi                          theta  phi'  theta'
    expected = np.array([[0, 0, -R * omega * math.sin(phi), 0, 0, R * math.cos(phi)],
                         [0, 0, R * omega * math.cos(phi), 0, 0, R * math.sin(phi)],
                         [0, 0, 0, 0, 1, 0],
                         [0, 0, 0, 0, 0, 1],
                         [0, 0, 0, 0, 0, 0],
                         [0, 0, 0, 0, 0, 0]])
    np.testing.assert_allclose(lin.A, expected, rtol=0, atol=1e-12)
    # the default choice (complete pivoting, ties to the earlier column) makes the contact
    # point's velocities the dependent ones
    default = lg.linearize_nonholonomic(disk, q, qd)
    assert default.speeds == ("phi_dot", "theta_dot")
    np.testing.assert_allclose(default.A, expected, rtol=0, atol=1e-12)


def test_unknown_speed_name_is_one_line(generated):
    with pytest.raises(lg.SimulationError, match="unknown name 'z'"):
        lg.linearize_nonholonomic(generated("chaplygin_sleigh"), [0, 0, 0], [1, 0, 0],
                                  speeds=("x", "z"))
