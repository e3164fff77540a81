"""dop853_impacts on models whose forces do work: W, the drag's work, is stepped with the state
(dop853's augmented W' = P) and continues across the impacts; the impulses' and the persistent
contact forces' work stays in saved["contact_work"]; E - E0 - W - contact_work closes at the
tolerance. A ball with linear air drag bouncing on the floor; a block with linear drag sliding
down a ramp with Coulomb friction (a persistent contact whose slip velocity is not linear in t,
so its friction work needs more than the trapezoid rule).

Closed forms (k = c / m): in flight v(t) = (v0 + g / k) e^(-k t) - g / k and
y(t) = y0 + (v0 + g / k)(1 - e^(-k t)) / k - g t / k; the landing is the root of y (brentq);
the rebound leaves with -e times the landing speed; the drag's work over a flight of length T is
-c int v^2 = -c (A^2 (1 - e^(-2kT)) / 2k - 2 A B (1 - e^(-kT)) / k + B^2 T), A = v0 + g / k,
B = g / k; an impact's work is -(1 - e^2) m v_-^2 / 2. The block slides along the ramp
(angle a) with u' = g (sin a - mu cos a) - k u: u = u_inf + (u0 - u_inf) e^(-k t),
u_inf = g (sin a - mu cos a) / k, path s(t) = u_inf t + (u0 - u_inf)(1 - e^(-k t)) / k;
friction's work -mu m g cos a s(t), the drag's -c int u^2.
"""

import math

import numpy as np
import pytest
from scipy.optimize import brentq

from lagrange_gen.codegen import generate_model
from lagrange_gen.run.loader import import_generated
from lagrange_gen.run.simulate import simulate

DRAG_BALL = '''
from lagrange_gen import Contact, Model, coordinates, parameters
y = coordinates("y")
m, g, e, c = parameters("m g e c", defaults=(1.0, 9.81, 0.8, 0.3))
model = Model("drag_ball", coords=[y], T=m * y.d**2 / 2, V=m * g * y, dissipation=c * y.d**2 / 2,
              contacts=[Contact(gap=y, restitution=e, name="floor")],
              description="Ball with linear air drag bouncing on the floor y = 0.")
'''
DRAG_RAMP = '''
from lagrange_gen import Contact, Model, coordinates, parameters
import sympy as sp
X, Y = coordinates("X Y")
m, g, a, mu, c = parameters("m g a mu c", defaults=(1.0, 9.81, 0.5, 0.3, 0.8))
model = Model("drag_ramp", coords=[X, Y], T=m * (X.d**2 + Y.d**2) / 2, V=m * g * Y,
              dissipation=c * (X.d**2 + Y.d**2) / 2,
              contacts=[Contact(gap=X * sp.sin(a) + Y * sp.cos(a), restitution=0, friction=mu,
                                slip=X.d * sp.cos(a) - Y.d * sp.sin(a), name="ramp")],
              description="Block with linear drag sliding on a ramp with Coulomb friction.")
'''
M, G, E, C, H0 = 1.0, 9.81, 0.8, 0.3, 1.0
K = C / M


def _generate(tmp_path_factory, name, text):
    folder = tmp_path_factory.mktemp(name)
    (folder / f"{name}.py").write_text(text)
    return import_generated(generate_model(folder / f"{name}.py", folder / "gen").path)


@pytest.fixture(scope="module")
def drag_ball(tmp_path_factory):
    return _generate(tmp_path_factory, "drag_ball", DRAG_BALL)


def flights(n):
    """(landing times, landing speeds, drag work and impact work up to each landing) of the
    first n flights from H0 at rest."""
    t0, y0, v0 = 0.0, H0, 0.0
    times, speeds, drag, impact = [], [], [0.0], [0.0]
    for _ in range(n):
        a, b = v0 + G / K, G / K

        def height(s, y0=y0, a=a):
            return y0 + a * (1 - math.exp(-K * s)) / K - b * s
        span = brentq(height, 1e-9, 10.0, xtol=1e-15, rtol=1e-15)
        v_land = a * math.exp(-K * span) - b
        drag.append(drag[-1] - C * (a * a * (1 - math.exp(-2 * K * span)) / (2 * K)
                                    - 2 * a * b * (1 - math.exp(-K * span)) / K + b * b * span))
        impact.append(impact[-1] - (1 - E * E) * M * v_land**2 / 2)
        t0 += span
        times.append(t0)
        speeds.append(v_land)
        y0, v0 = 0.0, -E * v_land
    return np.array(times), np.array(speeds), np.array(drag[1:]), np.array(impact[1:])


def test_drag_and_impacts_balance_the_energy(drag_ball):
    times, speeds, drag, impact = flights(3)
    traj = simulate(drag_ball, method="dop853_impacts", q0=[H0], v0=[0.0], t_end=times[-1] - 0.01,
                    rtol=1e-11, atol=1e-12)
    rows = np.flatnonzero(np.diff(traj.saved["impacts"][:, 0]) > 0) + 1
    assert len(rows) == 2
    assert np.abs(traj.t[rows] - times[:2]).max() < 1e-10
    assert np.abs(traj.v[rows - 1, 0] - speeds[:2]).max() < 1e-10
    # W is the drag's alone, the same before and after an impact (the impulse does no drag work)
    assert np.abs(traj.work[rows] - drag[:2]).max() < 1e-10
    np.testing.assert_array_equal(traj.work[rows], traj.work[rows - 1])
    assert np.abs(traj.saved["contact_work"][rows, 0] - impact[:2]).max() < 1e-10
    assert traj.work[-1] < -0.2
    residual = traj.energy - traj.energy[0] - traj.work - traj.saved["contact_work"][:, 0]
    assert np.abs(residual).max() < 1e-10
    assert np.abs(traj.energy_balance - traj.saved["contact_work"][:, 0]).max() < 1e-10


def test_dense_output_rows_carry_the_work(drag_ball):
    times, _, drag, _ = flights(2)
    t_eval = np.r_[np.linspace(0.1, times[1] - 0.01, 23), times[0]]
    traj = simulate(drag_ball, method="dop853_impacts", q0=[H0], v0=[0.0], t_end=times[1] - 0.01,
                    rtol=1e-11, atol=1e-12, t_eval=np.sort(t_eval))
    assert traj.work[np.searchsorted(traj.t, times[0])] == pytest.approx(drag[0], abs=1e-10)
    # the rows start at t_eval[0] > t0: differences from there (energy_balance subtracts W0)
    contact = traj.saved["contact_work"][:, 0]
    assert np.abs(traj.energy_balance - (contact - contact[0])).max() < 1e-10


def test_sliding_block_with_drag_balances_friction_and_drag(tmp_path_factory):
    """Launched down the ramp at u0 = 3 (it keeps sliding: u_inf = 2.5 > 0): few long steps
    (rtol = 1e-10), the friction work to 1e-10 of its closed form (the trapezoid rule on the
    friction power over those steps left 9e-3 in the balance)."""
    mod = _generate(tmp_path_factory, "drag_ramp", DRAG_RAMP)
    a, mu, c, u0, t_end = 0.5, 0.3, 0.8, 3.0, 2.0
    traj = simulate(mod, method="dop853_impacts", q0=[0.0, 0.0],
                    v0=[u0 * math.cos(a), -u0 * math.sin(a)], t_end=t_end, rtol=1e-10,
                    atol=1e-10)
    k = c / M
    u_inf = G * (math.sin(a) - mu * math.cos(a)) / k
    t = traj.t
    path = u_inf * t + (u0 - u_inf) * (1 - np.exp(-k * t)) / k
    aa, bb = u0 - u_inf, u_inf                   # u = aa e^(-k t) + bb
    drag = -c * (aa * aa * (1 - np.exp(-2 * k * t)) / (2 * k)
                 + 2 * aa * bb * (1 - np.exp(-k * t)) / k + bb * bb * t)
    assert (traj.saved["contact_mode"][:, 0] == 2).all()     # sliding downhill throughout
    assert traj.step_counts["accepted"] < 20
    assert np.abs(traj.saved["contact_work"][:, 0] + mu * M * G * math.cos(a) * path).max() \
        < 1e-10
    assert np.abs(traj.work - drag).max() < 1e-10
    residual = traj.energy - traj.energy[0] - traj.work - traj.saved["contact_work"][:, 0]
    assert np.abs(residual).max() < 1e-10
