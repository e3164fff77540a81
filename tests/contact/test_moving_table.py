"""Rheonomic contacts: a ball on a table whose height is h(t) = w t + A sin(Omega t)
(models/ball_on_moving_table.py, gap y - h(t)), against closed forms.

A table rising at the constant speed w (A = 0): relative to the table the ball falls from z0 = y0
at z' = -w under the same gravity (Galilean invariance), so the first impact is at the root
t1 of y0 - w t - g t^2 / 2, the relative impact speed U1 = sqrt(w^2 + 2 g y0), and after it the
relative motion is the ball on a fixed floor: rebound speeds e^k U1 relative to the table, the
k-th flight 2 e^k U1 / g long. The ball's own rebound velocity is w + e^k U1, not e^k times its
absolute impact speed: Newton's law acts on the velocity relative to the surface.

An oscillating table (w = 0): the first impact time is the root of the free flight's height
y0 - g t^2 / 2 minus the table's A sin(Omega t), found here by brentq; the rebound law on the
relative velocity, y'+ - h'(t1) = -e (y'- - h'(t1)) with h'(t1) = A Omega cos(Omega t1).
"""

import math

import numpy as np
import pytest
from scipy.optimize import brentq

from lagrange_gen.cli.main import main
from lagrange_gen.run.simulate import simulate

G, E, Y0, W = 9.81, 0.8, 1.0, 0.5
T1 = (-W + math.sqrt(W * W + 2 * G * Y0)) / G
U1 = math.sqrt(W * W + 2 * G * Y0)
AMPLITUDE, OMEGA, Y0_OSC = 0.05, 7.0, 0.3


@pytest.fixture(scope="module")
def table(generated):
    return generated("ball_on_moving_table")


def _impact_rows(traj):
    return np.flatnonzero(np.diff(traj.saved["impacts"][:, 0]) > 0) + 1


def test_rising_table_galilean_impacts(table):
    traj = simulate(table, method="dop853_impacts", q0=[Y0], v0=[0.0], t_end=3.0,
                    params={"g": G, "e": E, "w": W, "A": 0.0})
    rows = _impact_rows(traj)[:5]
    k = np.arange(len(rows))
    exact_t = T1 + np.concatenate([[0.0], np.cumsum(2 * E**(k[:-1] + 1) * U1 / G)])
    assert len(rows) == 5
    assert np.abs(traj.t[rows] - exact_t).max() <= 1e-10
    assert np.abs(traj.v[rows, 0] - (W + E**(k + 1) * U1)).max() <= 1e-10     # after
    assert np.abs(traj.v[rows - 1, 0] - (W - E**k * U1)).max() <= 1e-10        # before
    assert np.abs(traj.q[rows, 0] - W * traj.t[rows]).max() <= 1e-10            # on the table
    assert (traj.q[:, 0] - W * traj.t >= -1e-10).all()


def test_rising_table_moreau_jean_rebounds_on_the_relative_velocity(table):
    """In the impact step Newton's law holds exactly on the relative velocities at the step's
    ends: v+ - w = -e (v- - w); the first impact falls within a step of T1."""
    h = 1e-3
    traj = simulate(table, method="moreau_jean", q0=[Y0], v0=[0.0], t_end=0.6, h=h,
                    params={"g": G, "e": E, "w": W, "A": 0.0})
    k = np.flatnonzero(traj.saved["normal_impulse"][:, 0] > 0)[0]
    assert abs(traj.t[k - 1] - T1) <= h
    assert traj.v[k, 0] - W == pytest.approx(-E * (traj.v[k - 1, 0] - W), abs=1e-12)
    assert traj.v[k, 0] - W == pytest.approx(E * U1, abs=G * h)


def _oscillating_first_impact():
    def height(t):
        return Y0_OSC - G * t * t / 2 - AMPLITUDE * math.sin(OMEGA * t)
    t1 = brentq(height, 1e-6, math.sqrt(2 * (Y0_OSC + AMPLITUDE) / G) + 0.1, xtol=1e-15)
    table_speed = AMPLITUDE * OMEGA * math.cos(OMEGA * t1)
    before = -G * t1
    return t1, before, table_speed - E * (before - table_speed)


def test_oscillating_table_first_impact_and_rebound(table):
    t1, before, after = _oscillating_first_impact()
    traj = simulate(table, method="dop853_impacts", q0=[Y0_OSC], v0=[0.0], t_end=t1 + 0.01,
                    params={"g": G, "e": E, "w": 0.0, "A": AMPLITUDE, "Omega": OMEGA})
    rows = _impact_rows(traj)
    assert len(rows) == 1
    assert traj.t[rows[0]] == pytest.approx(t1, abs=1e-10)
    assert traj.v[rows[0] - 1, 0] == pytest.approx(before, abs=1e-9)
    assert traj.v[rows[0], 0] == pytest.approx(after, abs=1e-9)
    residual = traj.energy - traj.energy[0] - traj.saved["contact_work"][:, 0]
    assert np.abs(residual).max() <= 1e-11 * G * Y0_OSC


def test_the_cli_reports_the_first_impact_on_the_oscillating_table(table, capsys):
    t1, before, after = _oscillating_first_impact()
    assert main(["simulate", table.__file__, "--method", "dop853_impacts", "--t-end",
                 str(t1 + 0.01), "--q0", str(Y0_OSC), "--param",
                 f"g={G},e={E},w=0,A={AMPLITUDE},Omega={OMEGA}"]) == 0
    out = capsys.readouterr().out
    assert f"first t = {t1:.9g} (contact 0, p_N = {after - before:.6g})" in out, out
