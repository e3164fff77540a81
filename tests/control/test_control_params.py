"""Controllers inside the loop: the energy balance of a controlled run closes at the method's
order, and new gains passed as control_params run the loop already compiled."""

import numba
import numpy as np
import pytest

import lagrange_gen as lg
from control_util import torque_pendulum  # noqa: F401  (a fixture)

Q0, V0, T_END = [0.2, 0.6], [0.0, -0.4], 2.0


@numba.njit
def damp_and_drive(t, q, qd, p):
    return -0.8 * qd[1] + np.sin(3.0 * t)


def fit(steps, errors):
    return float(np.polyfit(np.log(1.0 / np.asarray(steps)), np.log(errors), 1)[0])


def test_balance_with_a_controller_closes_at_the_method_order(torque_pendulum):
    """midpoint (order 2) with u = -0.8 theta_dot + sin(3 t), held over each step: the work W
    of the held input closes E - E0 - W at order 2, as without a controller."""
    steps = (32, 64, 128, 256)
    errors = []
    for n in steps:
        tr = lg.simulate(torque_pendulum, "midpoint", Q0, V0, t_end=T_END, h=T_END / n,
                         control=damp_and_drive)
        errors.append(np.abs(tr.energy_balance).max())
    assert tr.max_energy_error > 0.1            # the controller does work
    slope = fit(steps, errors)
    assert abs(slope - 2) < 0.3, (slope, errors)
