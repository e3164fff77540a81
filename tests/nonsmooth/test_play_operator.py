"""HARD_CASES 11: the play operator, exact to round-off."""

import numpy as np
import pytest

from lagrange_gen.nonsmooth import loop_area, play_operator


def test_play_operator_plateaus_and_loop_area():
    k, eta = 2.0, 1.0
    up = np.round(np.arange(0, 301) * 0.01, 12)            # 0 -> 3
    down = np.round(3 - np.arange(1, 601) * 0.01, 12)      # 3 -> -3
    up2 = np.round(-3 + np.arange(1, 601) * 0.01, 12)      # -3 -> 3
    s = np.concatenate([up, down, up2])
    F = k * play_operator(s, eta)
    # Closed form per leg: elastic from the reversal point until |u| reaches eta.
    expected = np.concatenate([np.minimum(up, eta),                  # u = s, then eta
                               np.maximum(down - 2.0, -eta),         # u = eta - (3 - s)
                               np.minimum(up2 + 2.0, eta)])          # u = -eta + (s + 3)
    np.testing.assert_allclose(F, k * expected, atol=1e-13, rtol=0)
    assert F.max() == pytest.approx(2.0, abs=1e-13) and F.min() == pytest.approx(-2.0, abs=1e-13)
    # Plateaus: while loading with |u| = eta the force stays at +-k eta exactly.
    assert np.all(np.abs(F[(s > 1.0 + 1e-9) & (np.arange(len(s)) < 301)] - 2.0) < 1e-13)
    # The closed loop is the last two legs (3 -> -3 -> 3): area 4 k eta (S - eta) = 16.
    cycle = slice(300, None)
    assert abs(loop_area(s[cycle], F[cycle])) == pytest.approx(16.0, abs=1e-12)


def test_play_operator_refuses_nonpositive_threshold():
    with pytest.raises(ValueError, match="threshold eta must be > 0"):
        play_operator([0.0, 1.0], 0.0)
