"""nonholonomic_rk4 against closed forms: the vertical rolling disk (steady circular motion:
constant spin and turning rates, the circle of radius R omega / Omega, the constraint force
m R omega Omega towards the centre, conserved energy), the Chaplygin sleigh (u = U tanh(k t +
c), w = w0 cosh(c) / cosh(k t + c): the rotation dies out and the velocity ends constant along
the sleigh's axis; conserved energy) and a rheonomic belt x' = cos t (the db/dt term of gamma).

Why the tolerances: rk4 has global error C T h^4 with C of the order of the fifth derivative of
the solution, here at most rates^5 * amplitude (the disk: rho Omega^5 = 1.33 * 7.6 ~ 10; the
sleigh: rates k, w0 below 1.5), so at h = 0.01 over T = 10 to 40 the error bound is of order
1e-6 to 1e-5; the asserted 1e-7 is several hundred times the measured errors at h = 0.01
(disk 3.6e-10 over T = 10, sleigh 1.4e-10 over T = 10) and still far below an error of the
formulation (a wrong sign or a missing gamma term gives O(1)). The order test is the sharper
one: halving h must divide the error by about 2^4 = 16 (measured 16.0 and 15.8).
Energy and |A v + b| drift only at the local error's size, O(T h^4).
"""

import math

import numpy as np
import pytest
import sympy as sp

from lagrange_gen import Model, coordinates
from lagrange_gen.codegen import generate_model
from lagrange_gen.run.loader import import_generated
from lagrange_gen.run.simulate import simulate

METHOD = "nonholonomic_rk4"

# rolling_disk's defaults and a steady motion: spin omega, turning rate Omega, heading phi0.
M, R, I_SPIN, I_TURN = 1.0, 0.5, 0.125, 0.0625
OMEGA_SPIN, OMEGA_TURN, PHI0 = 4.0, 1.5, 0.3


def _disk(generated, h, t_end=10.0):
    v0 = [R * OMEGA_SPIN * math.cos(PHI0), R * OMEGA_SPIN * math.sin(PHI0), OMEGA_TURN,
          OMEGA_SPIN]
    return simulate(generated("rolling_disk"), METHOD, [0.0, 0.0, PHI0, 0.0], v0, t_end=t_end,
                    h=h)


def _disk_error(traj):
    """max |(x, y) - closed form| over the run: the contact point on the circle of radius
    rho = R omega / Omega through the origin, centre at rho (-sin phi0, cos phi0)."""
    rho, phi = R * OMEGA_SPIN / OMEGA_TURN, PHI0 + OMEGA_TURN * traj.t
    x = rho * (np.sin(phi) - math.sin(PHI0))
    y = -rho * (np.cos(phi) - math.cos(PHI0))
    return max(np.abs(traj.q[:, 0] - x).max(), np.abs(traj.q[:, 1] - y).max())


def test_disk_rolls_on_the_circle_of_radius_R_omega_over_Omega(generated):
    traj = _disk(generated, 0.01)
    assert _disk_error(traj) < 1e-7
    np.testing.assert_allclose(traj.v[:, 2], OMEGA_TURN, rtol=1e-12)
    np.testing.assert_allclose(traj.v[:, 3], OMEGA_SPIN, rtol=1e-12)
    # the contact point's speed R omega and the circle's centre stay put
    speed = np.hypot(traj.v[:, 0], traj.v[:, 1])
    np.testing.assert_allclose(speed, R * OMEGA_SPIN, rtol=1e-9)
    rho = R * OMEGA_SPIN / OMEGA_TURN
    centre = np.array([-rho * math.sin(PHI0), rho * math.cos(PHI0)])
    np.testing.assert_allclose(np.hypot(*(traj.q[:, :2] - centre).T), rho, rtol=1e-8)


def test_disk_constraint_force_is_the_centripetal_force(generated):
    """mu = m (x'', y'') = m R omega Omega (-sin phi, cos phi): towards the centre."""
    traj = _disk(generated, 0.01)
    phi, size = PHI0 + OMEGA_TURN * traj.t, M * R * OMEGA_SPIN * OMEGA_TURN
    np.testing.assert_allclose(traj.multipliers[:, 0], -size * np.sin(phi), atol=1e-9)
    np.testing.assert_allclose(traj.multipliers[:, 1], size * np.cos(phi), atol=1e-9)


def test_disk_energy_and_rolling_constraint_hold(generated):
    traj = _disk(generated, 0.01)
    E = (M * R**2 * OMEGA_SPIN**2 + I_SPIN * OMEGA_SPIN**2 + I_TURN * OMEGA_TURN**2) / 2
    np.testing.assert_allclose(traj.energy, E, rtol=1e-9)
    assert traj.saved["velocity_constraint_error"].max() < 1e-8


def test_disk_error_falls_as_h_to_the_fourth(generated):
    coarse, fine = (_disk_error(_disk(generated, h)) for h in (0.04, 0.02))
    assert 11.0 < coarse / fine < 22.0


# Chaplygin sleigh defaults (m, I, a) and an initial state turning fast, moving slowly.
SM, SI, SA = 1.0, 0.2, 0.5
U0, W0 = 0.3, 2.0


def _sleigh(generated, h, t_end):
    """Starts at theta = 0 with forward speed U0, turning rate W0 and the sideways velocity
    of the centre of mass the knife edge imposes, a W0."""
    return simulate(generated("chaplygin_sleigh"), METHOD, [0.0, 0.0, 0.0],
                    [U0, SA * W0, W0], t_end=t_end, h=h)


def _sleigh_closed_form(t):
    J = SI + SM * SA**2
    E = SM * U0**2 / 2 + J * W0**2 / 2
    U = math.sqrt(2 * E / SM)
    k, c = SM * SA * U / J, math.atanh(U0 / U)
    return U * np.tanh(k * t + c), W0 * math.cosh(c) / np.cosh(k * t + c), E, U


def _body_velocities(traj):
    th = traj.q[:, 2]
    u = traj.v[:, 0] * np.cos(th) + traj.v[:, 1] * np.sin(th)      # along the axis
    s = -traj.v[:, 0] * np.sin(th) + traj.v[:, 1] * np.cos(th)     # sideways
    return u, s, traj.v[:, 2]


def test_sleigh_follows_the_closed_form_and_ends_straight(generated):
    traj = _sleigh(generated, 0.01, 40.0)
    u, s, w = _body_velocities(traj)
    u_exact, w_exact, E, U = _sleigh_closed_form(traj.t)
    assert np.abs(u - u_exact).max() < 1e-7 and np.abs(w - w_exact).max() < 1e-7
    # asymptotically: no rotation, no sideways motion, speed U along the axis
    assert abs(w[-1]) < 1e-6 and abs(s[-1]) < 1e-6 and abs(u[-1] - U) < 1e-7
    np.testing.assert_allclose(traj.energy, E, rtol=1e-9)
    assert traj.saved["velocity_constraint_error"].max() < 1e-8


def test_sleigh_error_falls_as_h_to_the_fourth(generated):
    errors = []
    for h in (0.04, 0.02):
        traj = _sleigh(generated, h, 10.0)
        u, _, w = _body_velocities(traj)
        u_exact, w_exact, _, _ = _sleigh_closed_form(traj.t)
        errors.append(max(np.abs(u - u_exact).max(), np.abs(w - w_exact).max()))
    assert 11.0 < errors[0] / errors[1] < 22.0


def test_rheonomic_belt_gamma_has_db_dt(tmp_path):
    """A mass on a belt whose speed is cos t (x' = cos t) beside a free coordinate y:
    x = x0 + sin t, and the belt's force mu = m x'' = -sin t (m = 1); y moves freely."""
    path = tmp_path / "belt.py"
    path.write_text(
        "import sympy as sp\nfrom lagrange_gen import Model, coordinates, t\n"
        "x, y = coordinates('x y')\n"
        "model = Model('belt', coords=[x, y], T=(x.d**2 + y.d**2) / 2,\n"
        "              nonholonomic=[sp.Eq(x.d, sp.cos(t))])\n")
    module = import_generated(generate_model(path, tmp_path / "out").path)
    traj = simulate(module, METHOD, [0.2, 0.0], [1.0, 0.5], t_end=5.0, h=0.01)
    np.testing.assert_allclose(traj.q[:, 0], 0.2 + np.sin(traj.t), atol=1e-9)
    np.testing.assert_allclose(traj.q[:, 1], 0.5 * traj.t, atol=1e-12)
    np.testing.assert_allclose(traj.multipliers[:, 0], -np.sin(traj.t), atol=1e-9)
