"""Signal refuses samples it could not apply, in one line naming them (issue 34, item 5)."""

import numpy as np
import pytest

import lagrange_gen as lg
from lagrange_gen.run.control import Signal


@pytest.mark.parametrize("times, values, words", [
    ([0, np.nan, 1], [0, 5, 0], ("times", "finite", "nan")),
    ([0, np.inf], [0, 1], ("times", "finite")),
    ([], [], ("no samples",)),
    ([0, 1, 1], [0, 1, 2], ("increase", "times[2]")),
    ([0, 2, 1], [0, 1, 2], ("increase", "times[2]")),
    ([0, 1], [0, np.nan], ("values", "finite")),
    ([0, 1], [0, 1, 2], ("2 times", "3 samples")),
    ([[0, 1]], [0, 1], ("times", "1-d")),
    ([0, 1], np.zeros((2, 2, 2)), ("values",)),
    (["a", 1], [0, 1], ("times", "numbers")),
    ([0, 1], ["x", 1], ("values", "numbers")),
])
def test_bad_samples_are_one_line(times, values, words):
    with pytest.raises(lg.SimulationError) as err:
        Signal(times, values)
    text = str(err.value)
    assert "\n" not in text and text.startswith("Signal:"), text
    for word in words:
        assert word in text, text


def test_good_signal_still_applies_each_sample():
    signal = Signal([0.0, 1.0, 2.0], [0.0, 5.0, 0.0])
    assert signal(1.5)[0] == 5.0 and signal(0.5)[0] == 0.0
