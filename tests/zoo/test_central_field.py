"""Circular orbit in the central field V = -k m / sqrt(x^2 + y^2), Cartesian coordinates
(models/central_field.py), through every unconstrained stepper.

Closed forms: in polar coordinates the radial equation is m r'' = m r phi'^2 - k m / r^2, so
r = R is a solution when phi'^2 = k / R^3 =: omega^2. From the angle beta at t = 0:
    x = R cos(beta + omega t), y = R sin(beta + omega t), speed R omega = sqrt(k / R),
    period P = 2 pi R^1.5 / sqrt(k), E = m (R omega)^2 / 2 - k m / R = -k m / (2 R),
    ell = m (x y' - y x') = m R^2 omega = m sqrt(k R).

Orders measured here (h = P / steps):
- the trajectory error (against the closed form, over one period) has the method's order p;
- the return error after one period too, except symplectic Euler's, of order 2: it is conjugate
  to Stormer-Verlet through a half kick, which does not change the energy where the force is
  orthogonal to the velocity (everywhere on a circle), so no O(h) period error arises;
- the symplectic methods keep ell exactly (a quadratic invariant q^T A p of a symplectic
  partitioned method: Hairer-Lubich-Wanner GNI Thm. IV.2.4; midpoint: to its Newton tolerance),
  and the circle is the minimum of the effective potential at that ell, so E - E0 is quadratic
  in their O(h^p) radial deviation: energy error of order 2 p;
- the other methods' energy and ell errors are O(h^p) (global error), and may converge faster on
  this orbit (rk4: 5, measured), so only "at least p" is asserted for them.
"""

import math

import numpy as np
import pytest

from zoo_util import (SYMPLECTIC_METHODS, UNCONSTRAINED_METHODS, assert_model_allows_every_method,
                      assert_orders, order, roundoff_bound, run)

RADIUS, BETA = 1.3, 0.4
PARAMS = {"m": 2.0, "k": 1.5}
OMEGA = math.sqrt(PARAMS["k"] / RADIUS**3)
PERIOD = 2 * math.pi / OMEGA
SPEED = RADIUS * OMEGA
Q0 = RADIUS * np.array([math.cos(BETA), math.sin(BETA)])
V0 = SPEED * np.array([-math.sin(BETA), math.cos(BETA)])
ENERGY = -PARAMS["k"] * PARAMS["m"] / (2 * RADIUS)
ELL = PARAMS["m"] * math.sqrt(PARAMS["k"] * RADIUS)

# Steps per period, per order, in the asymptotic range (rk4's trajectory slope is 4.3 from 50 to
# 100 steps) and above roundoff for composition's order-8 energy error (2e-13 at 256 steps).
STEPS = {1: (800, 1600, 3200), 2: (100, 200, 400), 4: (64, 128, 256), 6: (32, 64, 128)}
SAVES_PER_PERIOD = 32
# Methods with an explicit path on constant H and velocity-free forces, which
# simulate(newton_always=True) replaces by their Newton path: both paths are checked.
EXPLICIT_PATH_METHODS = ("symplectic_euler", "verlet", "composition", "composition6")
CASES = [(m, False) for m in UNCONSTRAINED_METHODS]
CASES += [(m, True) for m in UNCONSTRAINED_METHODS if m in EXPLICIT_PATH_METHODS]


def circle(t):
    """Exact (q (S, 2), v (S, 2)) at times t (S,)."""
    angle = BETA + OMEGA * np.asarray(t)
    cos, sin = np.cos(angle), np.sin(angle)
    return RADIUS * np.column_stack([cos, sin]), SPEED * np.column_stack([-sin, cos])


def angular_momentum(q, v):
    return PARAMS["m"] * (q[:, 0] * v[:, 1] - q[:, 1] * v[:, 0])


def test_closed_form_is_a_solution_of_the_model(generated):
    """The closed form against the generated accelerations: x'' = -omega^2 x on the circle."""
    mod = generated("central_field")
    q, v = circle(np.array([0.0, 0.7]))
    for point, velocity in zip(q, v):
        qdd = mod.accelerations(point, velocity, params=PARAMS)
        np.testing.assert_allclose(qdd, -OMEGA**2 * point, rtol=1e-14)


@pytest.fixture(scope="module")
def central_field(generated):
    mod = generated("central_field")
    assert_model_allows_every_method(mod)
    return mod


def one_period_errors(mod, method, n_steps, newton_always):
    """{quantity: error} over one period of n_steps steps."""
    traj = run(mod, method, Q0, V0, PERIOD, n_steps, PARAMS,
               save_every=n_steps // SAVES_PER_PERIOD, newton_always=newton_always)
    q_exact, v_exact = circle(traj.t)
    return {"trajectory": max(np.abs(traj.q - q_exact).max(), np.abs(traj.v - v_exact).max()),
            "return": max(np.abs(traj.q[-1] - Q0).max(), np.abs(traj.v[-1] - V0).max()),
            "energy": np.abs(traj.energy - ENERGY).max(),
            "ell": np.abs(angular_momentum(traj.q, traj.v) - ELL).max()}


@pytest.mark.parametrize("method, newton_always", CASES)
def test_circular_orbit_errors_have_the_expected_orders(central_field, method, newton_always):
    steps = STEPS[order(method)]
    rows = [one_period_errors(central_field, method, n, newton_always) for n in steps]
    errors = {name: [row[name] for row in rows] for name in rows[0]}
    p = order(method)
    expected = {"trajectory": p, "return": 2 if method == "symplectic_euler" else p}
    if method in SYMPLECTIC_METHODS:
        for n, err in zip(steps, errors.pop("ell")):
            assert err <= roundoff_bound(ELL, n), (method, n, err)
        expected["energy"] = 2 * p
        assert_orders(method, steps, errors, expected)
    else:
        expected.update(energy=p, ell=p)
        assert_orders(method, steps, errors, expected, at_least=("energy", "ell"))
