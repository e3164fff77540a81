"""The plot of an adaptive run draws the motion between its saved rows, not straight chords.

dop853 integrates the bouncing ball's free flights (parabolas) exactly in one or two steps, so
its rows are the steps' ends and the impacts: drawn as chords, the ball looks flat after the
first impact. The plot draws each step as the cubic Hermite curve through (q, v) at its ends,
which is the parabola itself here: the drawn apex after impact k must be the closed form
e^(2k) h0 (and the drawn velocity the line through the rebound speed)."""

import math

import numpy as np
import pytest

from lagrange_gen.run.simulate import simulate

G, E, H0 = 9.81, 0.8, 1.0
V0, T1 = math.sqrt(2 * G * H0), math.sqrt(2 * H0 / G)


@pytest.fixture(scope="module")
def ball(generated):
    return simulate(generated("bouncing_ball"), method="dop853_impacts", q0=[H0], v0=[0.0],
                    t_end=3.0, params={"g": G, "e": E})


def _line(fig, label):
    (ax,) = [ax for ax in fig.axes if ax.get_ylabel() == label]
    (line,) = ax.get_lines()
    return np.asarray(line.get_xdata()), np.asarray(line.get_ydata())


def test_the_drawn_ball_rises_to_the_closed_form_apex_between_impacts(ball):
    impacts = ball.impacts["t"]
    assert len(impacts) >= 4
    t, y = _line(ball.plot(), "y")
    for k in range(1, 4):                         # the flights after impacts 1, 2, 3
        between = (t > impacts[k - 1]) & (t < impacts[k])
        assert abs(y[between].max() - E ** (2 * k) * H0) <= 1e-5 * H0
        # and it rises there at the rebound speed: the drawn apex time is mid-flight
        apex = t[between][np.argmax(y[between])]
        assert abs(apex - (impacts[k - 1] + E ** k * V0 / G)) <= 2e-3


def test_the_drawn_velocity_is_the_straight_line_of_each_flight(ball):
    impacts = ball.impacts["t"]
    t, v = _line(ball.plot(), "y_dot")
    k = 1
    between = (t > impacts[k - 1]) & (t < impacts[k])
    exact = E ** k * V0 - G * (t[between] - impacts[k - 1])
    assert np.abs(v[between] - exact).max() <= 1e-8 * V0
    # the jump at an impact is drawn at the impact time: before and after at the same t
    at = np.flatnonzero(t == impacts[0])
    assert sorted(np.round(v[at], 9)) == sorted(np.round([-V0, E * V0], 9))


def test_the_rows_themselves_stay_in_the_trajectory(ball):
    """The curve is only drawn: the Trajectory keeps the rows the run wrote."""
    t, y = _line(ball.plot(), "y")
    assert set(ball.t) <= set(t) and len(t) > len(ball.t)


def test_rows_with_an_impact_between_them_are_joined_straight(generated):
    """With t_eval the rows around an impact are on two flights: the cubic through them would
    dip below the floor; the plot joins them with a straight line instead (and draws the cubic
    between rows of one flight)."""
    traj = simulate(generated("bouncing_ball"), method="dop853_impacts", q0=[H0], v0=[0.0],
                    t_end=3.0, params={"g": G, "e": E}, t_eval=np.linspace(0, 3, 13))
    t, y = _line(traj.plot(), "y")
    assert y.min() >= -1e-12
    first = (t > 0) & (t < 0.25)                 # one flight: the free fall from rest
    np.testing.assert_allclose(y[first], H0 - G * t[first] ** 2 / 2, atol=1e-12)
