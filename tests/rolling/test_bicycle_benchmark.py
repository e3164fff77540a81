"""The Whipple bicycle benchmark: models/bicycle.py (the full nonlinear model: 8 coordinates,
the front wheel's contact as a holonomic constraint, four rolling constraints) linearized by
lagrange_gen.linearize_nonholonomic about upright straight running must give the published
linearized equations M q'' + v C1 q' + (g K0 + v^2 K2) q = 0 in q = (lean phi, steer delta).

Reference: Meijaard, Papadopoulos, Ruina, Schwab, "Linearized dynamics equations for the balance
and steer of a bicycle: a benchmark and review", Proc. R. Soc. A 463 (2007) 1955-1982: the
matrices of section 5 (eq. 5.x, 14 digits) and Table 2 (eigenvalues at several speeds, the
weave, capsize and bifurcation speeds, 14 digits). Nothing here feeds the published numbers to
the linearization: they are compared with what the generated kernels give.

Why the tolerances: the published values carry 14 significant digits and our linearization is
exact up to round-off (exact derivative kernels, solves of condition ~1e3), so 1e-10 on the
matrices; the speeds are roots of eigenvalues that cross zero with slopes of order 1 per m/s,
found to 1e-12 by brentq, compared to 1e-8.
"""

import numpy as np
import pytest
from scipy.optimize import brentq

import lagrange_gen as lg

G, R_REAR, R_FRONT = 9.81, 0.3, 0.35

PUBLISHED = {
    "M": [[80.81722, 2.31941332208709], [2.31941332208709, 0.29784188199686]],
    "C1": [[0.0, 33.86641391492494], [-0.85035641456978, 1.68540397397560]],
    "K0": [[-80.95, -2.59951685249872], [-2.59951685249872, -0.80329488458618]],
    "K2": [[0.0, 76.59734589573222], [0.0, 2.65431523794604]],
}
# Table 2: eigenvalues (s^-1) at forward speeds v (m/s), and the characteristic speeds.
PUBLISHED_EIGENVALUES = {
    0.0: [-5.53094371765393, -3.13164324790656, 3.13164324790656, 5.53094371765393],
    4.0: [-12.15861426576447, -1.42944427361326, 0.41325331521125 - 3.07910818603206j,
          0.41325331521125 + 3.07910818603206j],
    5.0: [-14.07838969279822, -0.32286642900409, -0.77534188219585 - 4.46486771378823j,
          -0.77534188219585 + 4.46486771378823j],
    10.0: [-24.62459635017404, 0.16105338653172, -3.72016840437287 - 10.90681139476287j,
           -3.72016840437287 + 10.90681139476287j],
}
WEAVE_SPEED, CAPSIZE_SPEED = 4.29238253634111, 6.02426201538837
BIFURCATION_SPEED = 0.68428307889246   # the two real weave eigenvalues merge into a pair

SPEEDS = ("phi", "delta", "theta_R")


@pytest.fixture(scope="module")
def bicycle(generated):
    return generated("bicycle")


def upright(v):
    """q, qd of upright straight running at the rear contact's speed v (x forward)."""
    q, qd = np.zeros(8), np.zeros(8)
    qd[0], qd[6], qd[7] = v, -v / R_REAR, -v / R_FRONT
    return q, qd


def lean_steer(bicycle, v, g=G):
    """(M, C, K) (2, 2) of the lean and steer rows and columns of the reduced linearization."""
    lin = lg.linearize_nonholonomic(bicycle, *upright(v), params={"g": g}, speeds=SPEEDS)
    assert lin.speeds == ("phi_dot", "delta_dot", "theta_R_dot")
    rows, cols = [0, 1], [lin.coordinates.index("phi"), lin.coordinates.index("delta")]
    return (lin.mass[np.ix_(rows, rows)], lin.damping[np.ix_(rows, rows)],
            lin.stiffness[np.ix_(rows, cols)])


def benchmark_eigenvalues(bicycle, v):
    """The four eigenvalues of the lean/steer system at speed v, sorted."""
    M, C, K = lean_steer(bicycle, v)
    A = np.block([[np.zeros((2, 2)), np.eye(2)],
                  [-np.linalg.solve(M, K), -np.linalg.solve(M, C)]])
    return np.sort_complex(np.linalg.eigvals(A))


def test_linearized_matrices_equal_the_published_ones(bicycle):
    M0, C0, K0g = lean_steer(bicycle, 0.0)
    M1, C1, K1 = lean_steer(bicycle, 1.0)
    M3, C3, K3 = lean_steer(bicycle, 3.0)
    got = {"M": M0, "C1": C1, "K0": K0g / G, "K2": K1 - K0g}
    for name, matrix in got.items():
        np.testing.assert_allclose(matrix, PUBLISHED[name], rtol=0, atol=1e-10, err_msg=name)
    # the structure M, v C1, g K0 + v^2 K2: no other dependence on v
    np.testing.assert_allclose(M3, M0, rtol=0, atol=1e-10)
    np.testing.assert_allclose(C3, 3.0 * C1, rtol=0, atol=1e-10)
    np.testing.assert_allclose(K3, K0g + 9.0 * (K1 - K0g), rtol=0, atol=1e-9)
    # and g enters only K0
    np.testing.assert_allclose(lean_steer(bicycle, 1.0, g=0.0)[2], K1 - K0g, rtol=0, atol=1e-10)


@pytest.mark.parametrize("v", sorted(PUBLISHED_EIGENVALUES))
def test_eigenvalues_equal_table_2(bicycle, v):
    np.testing.assert_allclose(benchmark_eigenvalues(bicycle, v),
                               np.sort_complex(PUBLISHED_EIGENVALUES[v]), rtol=0, atol=1e-10)


def test_reduced_state_space_holds_the_benchmark_eigenvalues(bicycle):
    """lg.linearize's (z, u) system (7 coordinates, 3 speeds): the four benchmark eigenvalues
    and six zeros (the position, heading, wheel angles and the forward speed are neutral)."""
    lin = lg.linearize(bicycle, *upright(5.0), speeds=SPEEDS)
    assert lin.A.shape == (10, 10)
    eig = np.linalg.eigvals(lin.A)
    small = np.abs(eig) < 1e-8
    assert small.sum() == 6
    np.testing.assert_allclose(np.sort_complex(eig[~small]),
                               np.sort_complex(PUBLISHED_EIGENVALUES[5.0]), rtol=0, atol=1e-10)


def test_weave_capsize_and_bifurcation_speeds(bicycle):
    def weave_real_part(v):
        eig = benchmark_eigenvalues(bicycle, v)
        return max(e.real for e in eig if abs(e.imag) > 1e-9)

    def capsize_eigenvalue(v):      # the real eigenvalue nearest zero (it crosses at v_c)
        eig = benchmark_eigenvalues(bicycle, v)
        real = [e.real for e in eig if abs(e.imag) <= 1e-9]
        return min(real, key=abs)

    v_w = brentq(weave_real_part, 3.0, 5.0, xtol=1e-13)
    v_c = brentq(capsize_eigenvalue, 5.5, 6.5, xtol=1e-13)
    assert abs(v_w - WEAVE_SPEED) < 1e-8
    assert abs(v_c - CAPSIZE_SPEED) < 1e-8
    # self-stable between them: every eigenvalue in the left half plane
    assert np.max(benchmark_eigenvalues(bicycle, 0.5 * (v_w + v_c)).real) < 0
    assert np.max(benchmark_eigenvalues(bicycle, v_w - 0.1).real) > 0
    assert np.max(benchmark_eigenvalues(bicycle, v_c + 0.1).real) > 0
    # at v_b the weave pair is born from two real roots
    assert np.all(np.abs(benchmark_eigenvalues(bicycle, BIFURCATION_SPEED - 1e-3).imag) < 1e-9)
    assert np.any(np.abs(benchmark_eigenvalues(bicycle, BIFURCATION_SPEED + 1e-3).imag) > 1e-3)


def test_off_the_constraints_is_refused_in_one_line(bicycle):
    q, qd = upright(4.0)
    qd[1] = 0.3                         # sideways slip of the rear contact
    with pytest.raises(lg.SimulationError, match="violates the constraints"):
        lg.linearize_nonholonomic(bicycle, q, qd, speeds=SPEEDS)
    with pytest.raises(lg.SimulationError, match="3 independent speeds"):
        lg.linearize_nonholonomic(bicycle, *upright(4.0), speeds=("phi", "delta"))


def test_nonlinear_bicycle_follows_its_linearization(bicycle):
    """The nonlinear model stepped by nonholonomic_midpoint (the front wheel's contact as a
    holonomic constraint beside the four rolling ones) at v = 5 m/s, self-stable, from a lean
    rate of 0.05 rad/s: its lean and steer follow exp(A t) of the reduced linearization to
    O(h^2) + O(amplitude^2) (measured 1.7e-5 of a 0.0105 rad swing at h = 0.01; asserted 1e-4),
    the constraints hold to round-off and the energy to O(h^2) (measured 1.3e-6)."""
    from scipy.linalg import expm
    q, qd = upright(5.0)
    lin = lg.linearize_nonholonomic(bicycle, q, qd, speeds=SPEEDS)
    qd[3] = 0.05
    traj = lg.simulate(bicycle, "nonholonomic_midpoint", q, qd, t_end=4.0, h=0.01)
    x0 = np.zeros(lin.A.shape[0])
    x0[len(lin.coordinates)] = 0.05                       # the lean rate, first speed
    linear = np.array([expm(lin.A * t) @ x0 for t in traj.t])
    for name, column in (("phi", 3), ("delta", 5)):
        np.testing.assert_allclose(traj.q[:, column], linear[:, lin.coordinates.index(name)],
                                   rtol=0, atol=1e-4, err_msg=name)
    assert np.abs(traj.q[:, 3]).max() > 0.01 and abs(traj.q[-1, 3]) < 0.003   # it recovers
    assert traj.saved["velocity_constraint_error"].max() < 1e-12
    assert traj.saved["position_constraint_error"].max() < 1e-12
    assert np.abs(traj.energy - traj.energy[0]).max() < 1e-5
