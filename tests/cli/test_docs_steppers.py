"""The docs' stepper table (docs/guides/choosing-a-method.md) lists every method with its order,
and the multiplier sign the constraints guide states is the code's: the Cartesian pendulum hanging at rest at (0, -l), Phi =
(x^2 + y^2 - l^2)/2, J = (x, y), g = dV/dq = (0, m g); H qdd = Q - h - g + J^T lam = 0 gives
J^T lam = (0, m g) (the rod holds the bob up), lam = -m g / l, as the guide says."""

import re
from pathlib import Path

import numpy as np
import pytest

from lagrange_gen.run.simulate import simulate
from lagrange_gen.steppers.core import registry

GUIDES = Path(__file__).resolve().parents[2] / "docs" / "guides"
METHODS_PAGE = (GUIDES / "choosing-a-method.md").read_text()
CONSTRAINTS_PAGE = (GUIDES / "constraints.md").read_text()


def _table():
    """{method: order} of the table under '## The methods'."""
    section = METHODS_PAGE.split("## The methods", 1)[1].split("\n## ", 1)[0]
    rows = re.findall(r"^\| ([a-z0-9_]+) \| (\d+) \|", section, flags=re.M)
    return {name: int(order) for name, order in rows}


def test_table_lists_every_method_with_its_order():
    table = _table()
    assert list(table) == list(registry.METHODS)
    assert table == {m: registry.spec(m).order for m in registry.METHODS}
    assert "J(q)^T lam" in CONSTRAINTS_PAGE and "lam = -m g / l = -9.81" in CONSTRAINTS_PAGE


@pytest.mark.parametrize("method", registry.CONSTRAINED_METHODS)
def test_multiplier_sign_is_the_guides(generated, method):
    module = generated("cartesian_pendulum")
    m, l, g = (dict(zip(module.PARAMS, module.DEFAULTS))[k] for k in ("m", "l", "g"))
    traj = simulate(module, method, [0.0, -l], [0.0, 0.0], t_end=0.01, h=1e-3)
    np.testing.assert_allclose(traj.multipliers[:, 0], -m * g / l, rtol=1e-9)
