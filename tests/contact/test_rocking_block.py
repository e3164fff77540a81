"""The rocking block (models/rocking_block.py, Housner 1963) under moreau_jean, against closed
forms. Block of half-width b = 0.2, half-height c = 0.6 (alpha = atan(b / c), R = sqrt(b^2 + c^2),
I_A = 4/3 m R^2 about a corner), friction mu = 1 (no sliding below a_ground = g), e = 0.

* Onset: on ground accelerating with a_ground the block, at rest on both corners, rocks about
  the rear corner when the inertial moment m a c passes the gravity moment m g b, i.e. for
  a_ground > g b / c; below it the contact problem of each step finds impulses at both corners
  that hold it (Moreau-Jean needs no threshold: a normal impulse would have to become negative).
* Pivoting about a corner (the left one, at rest on the ground, a_ground > g b / c): the energy
  first integral I_A phi'^2 / 2 = -(V(phi) - V(0)) with
  V(phi) = m g (b sin phi + c cos phi) + m a (b cos phi - c sin phi).
* Impact on the other corner (released tilted by phi0 = 0.15 on the left corner, a_ground = 0):
  angular momentum about the right corner is conserved by the plastic impact and the left corner
  lifts, so phi'+ / phi'- = 1 - 3/2 sin^2 alpha and the kinetic energy keeps
  r = (1 - 3/2 sin^2 alpha)^2 = 0.7225.

Tolerances: moreau_jean is order 1. At the impact, the kinetic energy is read at the start and
the end of the impact step, over which gravity's power m g b phi' also changes it: a relative
error up to 2 g b h / ((I_A / m) phi') (8.0 h here, measured 6.1 h), halving with h (asserted:
order 1). In the pivoting phase the velocity error against the first integral is first order too
(measured 6.2e-3 at h = 1e-3, 3.1e-3 at h / 2): bound 10 h rad/s and the halving. Holding the
block below the onset is exact up to the contact problem's tolerance (contact_tol = 1e-10
relative): measured |phi| <= 1.5e-12 after 0.5 s.
"""

import math

import numpy as np
import pytest

from lagrange_gen.run.simulate import simulate

G, B, C = 9.81, 0.2, 0.6
R, ALPHA = math.hypot(B, C), math.atan2(B, C)
I_CORNER = 4 / 3 * R**2          # per unit mass
ONSET = G * B / C                # Housner's critical ground acceleration g tan(alpha)


def _block(generated, q0, h, t_end, a_ground=0.0):
    return simulate(generated("rocking_block"), method="moreau_jean", q0=q0, t_end=t_end, h=h,
                    params={"g": G, "b": B, "c": C, "e": 0.0, "mu": 1.0, "a_ground": a_ground})


@pytest.mark.parametrize("fraction", [0.5, 0.99])
def test_block_stays_below_housners_onset(generated, fraction):
    traj = _block(generated, [0.0, C, 0.0], 1e-3, 0.5, fraction * ONSET)
    assert np.abs(traj.q[:, 2]).max() <= 1e-10 and np.abs(traj.v).max() <= 1e-10
    assert np.all(traj.saved["active_contacts"][1:, 0] == 2)


def _pivot_error(generated, h, a):
    traj = _block(generated, [0.0, C, 0.0], h, 0.5, a)
    phi, rate = traj.q[:, 2], traj.v[:, 2]
    potential = G * (B * np.sin(phi) + C * np.cos(phi) - C) + a * (B * np.cos(phi) - C * np.sin(phi) - B)
    exact = np.sqrt(np.maximum(-2 * potential / I_CORNER, 0.0))
    return traj, np.abs(rate - exact).max()


@pytest.mark.parametrize("fraction", [1.01, 1.5])
def test_block_rocks_above_housners_onset_about_its_rear_corner(generated, fraction):
    a = fraction * ONSET
    traj, error = _pivot_error(generated, 1e-3, a)
    phi = traj.q[:, 2]
    assert phi[-1] > 0 and np.all(np.diff(phi) >= 0)
    assert error <= 10 * 1e-3
    # once rocking has begun only the left (rear) corner carries the block (not in every step:
    # the pivot drifts off the ground by O(h^2) at the position level, skips a step's impulse
    # and takes twice the impulse in the next one; measured at a = 1.5 g b / c)
    rocking = phi > 0
    assert np.all(traj.saved["normal_impulse"][rocking, 1] == 0)
    if fraction == 1.5:
        _, finer = _pivot_error(generated, 5e-4, a)
        assert 1.7 <= error / finer <= 2.3


def _impact_ratio(generated, h, phi0=0.15):
    """Kinetic energy after / before the first impact on the right corner, and the left corner's
    normal impulse in that step."""
    x = -B + B * math.cos(phi0) - C * math.sin(phi0)      # left corner at the origin
    y = B * math.sin(phi0) + C * math.cos(phi0)
    traj = _block(generated, [x, y, phi0], h, 0.5)
    kinetic = traj.energy - G * traj.q[:, 1]
    k = np.flatnonzero(traj.saved["normal_impulse"][:, 1] > 0)[0]    # end of the impact step
    return kinetic[k] / kinetic[k - 1], traj.saved["normal_impulse"][k, 0]


def test_plastic_impact_keeps_housners_energy_fraction(generated):
    r = (1 - 1.5 * math.sin(ALPHA)**2) ** 2
    h = 1e-3
    ratio, left_impulse = _impact_ratio(generated, h)
    phi_rate = math.sqrt(2 * G * R * (math.cos(ALPHA - 0.15) - math.cos(ALPHA)) / I_CORNER)
    assert abs(ratio - r) <= 2 * G * B * h / (I_CORNER * phi_rate)
    assert left_impulse == 0.0           # the left corner lifts: Housner's assumption holds
    finer, _ = _impact_ratio(generated, h / 2)
    assert 1.7 <= (ratio - r) / (finer - r) <= 2.3
