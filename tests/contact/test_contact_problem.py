"""The contact problem's 3D Coulomb law (steppers/core/contact_problem.py) checked by the
conditions that define it, on one contact whose Delassus block is not a multiple of the
identity (where a radial projection of the sticking pair would break the law):

sticking: u_N = 0, u_T = 0 and |p_T| <= mu p_N; sliding: u_N = 0, |p_T| = mu p_N and the slip
u_T opposite to p_T (u_T = -lambda p_T with lambda > 0: maximal dissipation)."""

import numpy as np
import pytest

from lagrange_gen.steppers.core import contact_problem as cp

MU = 0.5
# an SPD Delassus matrix (normal, tangent 1, tangent 2) with an anisotropic, coupled tangent block
D = np.array([[2.0, 0.3, -0.2], [0.3, 1.0, 0.6], [-0.2, 0.6, 3.0]])


def _solve(uf):
    active = np.ones(1)
    law = np.array([cp.UNILATERAL, cp.COULOMB], dtype=np.int64)
    coef = np.array([[0.0, MU]])
    r = np.zeros(3)
    converged, _, _ = cp.gauss_seidel(1, 1e-14, 10000, active, law, coef, np.zeros(1),
                                      np.asarray(uf, float), D, r)
    assert converged
    return r, np.asarray(uf, float) + D @ r


def test_sticking_pair_zeroes_the_slip_inside_the_disk():
    exact = np.array([1.0, 0.1, -0.1])             # |p_T| = 0.14 < mu p_N
    r, u = _solve(-D @ exact)
    assert np.abs(r - exact).max() <= 1e-12 and np.abs(u).max() <= 1e-12


@pytest.mark.parametrize("uf", [[-1.0, 2.0, 0.5], [-1.0, -0.3, 4.0], [-0.5, 1.0, -1.0]])
def test_sliding_pair_is_on_the_circle_and_opposes_the_slip(uf):
    r, u = _solve(uf)
    pt, ut = r[1:], u[1:]
    assert abs(u[0]) <= 1e-12 and r[0] > 0
    assert np.hypot(*pt) == pytest.approx(MU * r[0], rel=1e-12)
    # u_T = -lambda p_T, lambda > 0: no component of the slip across the impulse
    assert abs(pt[0] * ut[1] - pt[1] * ut[0]) <= 1e-10 * np.hypot(*pt) * np.hypot(*ut)
    assert pt @ ut < 0


def test_one_tangent_is_the_interval():
    """A zero second tangent row (the 2D law): p_T1 clamped to [-mu p_N, mu p_N], p_T2 = 0."""
    D2 = D.copy()
    D2[2, :] = D2[:, 2] = 0.0
    r = np.zeros(3)
    cp.gauss_seidel(1, 1e-14, 10000, np.ones(1), np.array([0, 0], dtype=np.int64),
                    np.array([[0.0, MU]]), np.zeros(1), np.array([-1.0, 2.0, 0.0]), D2, r)
    assert r[2] == 0.0 and r[1] == pytest.approx(-MU * r[0], rel=1e-12)
