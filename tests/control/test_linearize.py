"""linearize and equilibrium against closed forms and finite differences of the generated
dynamics; the LQR closed loop through a jitted controller inside simulate."""

import numba
import numpy as np
import pytest
import scipy.linalg

import lagrange_gen as lg
from control_util import torque_pendulum  # noqa: F401  (a fixture)
from lagrange_gen.linear.linearize import parameter_vector


def test_cart_pole_linearization_matches_hand_derived(generated):
    """Upright cart pole: H = [[M+m, m l], [m l, m l^2]], rhs = [u - c xd, m g l th] to first
    order, so xdd = (u - c xd)/M - m g th/M, thdd = -(u - c xd)/(M l) + (M+m) g th/(M l)."""
    module = generated("cart_pole")
    M, m, l, g, c = 1.0, 0.3, 0.5, 9.81, 0.1
    A, B, C, D = lg.linearize(module, [0.7, 0.0], [0.0, 0.0], u=[0.0])
    expect_A = np.array([[0, 0, 1, 0], [0, 0, 0, 1], [0, -m * g / M, -c / M, 0],
                         [0, (M + m) * g / (M * l), c / (M * l), 0]])
    np.testing.assert_allclose(A, expect_A, atol=1e-14)
    np.testing.assert_allclose(B, [[0], [0], [1 / M], [-1 / (M * l)]], atol=1e-14)
    np.testing.assert_allclose(C, [[1, 0, 0, 0], [1, l, 0, 0]], atol=1e-14)   # cart, tip_x
    np.testing.assert_allclose(D, np.zeros((2, 1)))


def _fd_jacobian(f, x, eps=1e-6):
    cols = [(f(x + eps * e) - f(x - eps * e)) / (2 * eps) for e in np.eye(len(x))]
    return np.array(cols).T


def test_linearization_matches_finite_differences_off_equilibrium(torque_pendulum):
    """At a moving state with u != 0: A, B, C, D against central differences of the generated
    accelerations and outputs."""
    mod, n = torque_pendulum, 2
    q, qd, u = np.array([0.3, 0.9]), np.array([-0.4, 1.1]), 0.7
    A, B, C, D = lg.linearize(mod, q, qd, u=[u], t=0.0)

    def f(z):      # z = (q, qd, u) -> (qd, qdd, y)
        p = parameter_vector(mod, None, [z[-1]])
        qq, vv = np.ascontiguousarray(z[:n]), np.ascontiguousarray(z[n:2 * n])
        y = np.zeros(2)
        mod.outputs(qq, vv, 0.0, p, y)
        return np.concatenate((vv, mod.accelerations(qq, vv, 0.0, p), y))

    J = _fd_jacobian(f, np.concatenate((q, qd, [u])))
    np.testing.assert_allclose(A, J[:2 * n, :2 * n], rtol=1e-7, atol=1e-7)
    np.testing.assert_allclose(B, J[:2 * n, 2 * n:], rtol=1e-7, atol=1e-7)
    np.testing.assert_allclose(C, J[2 * n:, :2 * n], rtol=1e-7, atol=1e-7)
    np.testing.assert_allclose(D, J[2 * n:, 2 * n:], rtol=1e-7, atol=1e-7)


def test_equilibrium_closed_form(torque_pendulum):
    """Rest with a constant torque: x = 0 (spring), m g l sin(theta) = u cos(0)."""
    m, l, g, u = 0.5, 0.8, 9.81, 1.3
    q = lg.equilibrium(torque_pendulum, [0.2, 0.1], u=[u])
    np.testing.assert_allclose(q, [0.0, np.arcsin(u / (m * g * l))], atol=1e-12)


def test_constrained_pendulum_minimal_coordinates(generated):
    """Cartesian pendulum (x, y; x^2 + y^2 = l^2): equilibrium (0, -l) from a guess off the
    circle; linearized in the one minimal coordinate, A = [[0, 1], [-g/l, 0]]."""
    module = generated("cartesian_pendulum")
    q = lg.equilibrium(module, [0.3, -0.8])
    np.testing.assert_allclose(q, [0.0, -1.0], atol=1e-12)
    A, B, C, D = lg.linearize(module, q, [0.0, 0.0])
    np.testing.assert_allclose(A, [[0, 1], [-9.81, 0]], atol=1e-12)
    assert B.shape == (2, 0) and C.shape == (0, 2)
    A2, _, _, _ = lg.linearize(module, [np.sin(0.4), -np.cos(0.4)], [0.0, 0.0])
    # off rest: d(thdd)/dth = -g cos(th) / l for thdd = -g sin(th)/l, and the tangent is unit
    np.testing.assert_allclose(A2[1, 0], -9.81 * np.cos(0.4), rtol=1e-10)


def test_equilibrium_failure_is_one_line(generated):
    with pytest.raises(lg.SimulationError, match="equilibrium: Newton did not converge"):
        lg.equilibrium(generated("cart_pole"), [0.0, 0.5], u=[1.0], max_iter=3)


def test_lqr_stabilizes_the_inverted_cart_pole(generated):
    """LQR from linearize (scipy's CARE) keeps the pendulum up and brings the cart home, the
    controller running inside the loop; without it the pendulum falls."""
    module = generated("cart_pole")
    A, B, _, _ = lg.linearize(module, [0.0, 0.0], [0.0, 0.0], u=[0.0])
    Q, R = np.diag([10.0, 100.0, 1.0, 1.0]), np.array([[1.0]])
    P = scipy.linalg.solve_continuous_are(A, B, Q, R)
    K = np.linalg.solve(R, B.T @ P)[0]

    @numba.njit
    def lqr(t, q, qd, p):
        return -(K[0] * q[0] + K[1] * q[1] + K[2] * qd[0] + K[3] * qd[1])

    traj = lg.simulate(module, "midpoint", q0=[0.5, 0.25], t_end=10.0, h=1e-2, control=lqr)
    assert np.max(np.abs(traj.q[-1])) < 1e-3 and np.max(np.abs(traj.v[-1])) < 1e-3
    np.testing.assert_allclose(traj.saved["input_u"][:, 0],
                               -(np.hstack((traj.q, traj.v)) @ K), atol=1e-12)
    free = lg.simulate(module, "midpoint", q0=[0.5, 0.25], t_end=3.0, h=1e-2, params={"u": 0.0})
    assert np.max(np.abs(free.q[:, 1])) > 1.0


def test_controlled_run_gives_no_energy_warning(torque_pendulum):
    """A torque that works and then stops leaves u = 0 in p at the end, where the model is
    conservative: the energy warning must not blame the step for the work of the input."""
    import warnings

    @numba.njit
    def kick(t, q, qd, p):
        return 3.0 if t < 0.5 else 0.0

    with warnings.catch_warnings():
        warnings.simplefilter("error", lg.EnergyWarning)
        traj = lg.simulate(torque_pendulum, "rk4", q0=[0.0, 0.1], t_end=1.0, h=1e-3, control=kick)
    assert abs(traj.energy[-1] - traj.energy[0]) > 0.1 and not traj.warnings


def test_constrained_acceleration_derivatives_off_rest(generated):
    """The KKT derivatives (d(qdd)/dq, d(qdd)/dqd of H qdd = rhs + J^T lam, J qdd = gamma) at a
    moving state of the four-bar linkage (trigonometric constraints: d gamma/dq != 0), against
    central differences of the KKT solve of the generated kernels."""
    from lagrange_gen.linear.linearize import accel_jacobians
    mod = generated("four_bar")
    n, m, p = mod.N_COORDS, mod.N_CONSTRAINTS, mod.DEFAULT_PARAMS.copy()
    q, qd = np.array([0.7, 0.4, 1.9]), np.array([1.1, -0.6, 0.8])

    def kkt(z):
        qq, vv = np.ascontiguousarray(z[:n]), np.ascontiguousarray(z[n:])
        H, rhs, phi, J, gamma = np.zeros((n, n)), np.zeros(n), np.zeros(m), np.zeros((m, n)), np.zeros(m)
        mod.dynamics(qq, vv, 0.0, p, H, rhs)
        mod.constraints(qq, vv, 0.0, p, phi, J, gamma)
        K = np.block([[H, -J.T], [J, np.zeros((m, m))]])
        return np.linalg.solve(K, np.concatenate((rhs, gamma)))[:n]

    _, _, dq, dqd, _ = accel_jacobians(mod, q, qd, 0.0, p)
    fd = _fd_jacobian(kkt, np.concatenate((q, qd)))
    np.testing.assert_allclose(dq, fd[:, :n], rtol=1e-6, atol=1e-6)
    np.testing.assert_allclose(dqd, fd[:, n:], rtol=1e-6, atol=1e-6)


def test_a_model_without_inputs_says_why_B_has_no_columns(generated):
    """cart_pendulum declares no inputs: B (4, 0), and one warning line saying why and how to
    declare one; a model with inputs linearizes without it."""
    import warnings
    expected = (r"^cart_pendulum has no inputs, so B and D have 0 columns: "
                r".*inputs=\[u\].*models/cart_pendulum_forced\.py")
    with pytest.warns(UserWarning, match=expected) as got:
        A, B, C, D = lg.linearize(generated("cart_pendulum"), [0.0, 0.0], [0.0, 0.0])
    assert B.shape == (4, 0) and A.shape == (4, 4)
    message = str(got[0].message)
    assert len(got) == 1 and "\n" not in message and "frozen" not in message
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        lg.linearize(generated("cart_pole"), [0.0, 0.0], [0.0, 0.0], u=[0.0])


def test_forced_cart_pendulum_is_the_cart_pendulum_with_a_force_input(generated):
    """models/cart_pendulum_forced.py: the energies of models/cart_pendulum.py, and at the
    hanging equilibrium H = [[M+m, m l], [m l, m l^2]], stiffness diag(k, m g l), force (u, 0):
    A = [[0, I], [-H^-1 K, 0]], B = [0; H^-1 (1, 0)] = [0, 0, 1/M, -1/(M l)]."""

    from lagrange_gen.model.model_file import load_model
    from lg_test_support import MODELS_DIR
    plain = load_model(MODELS_DIR / "cart_pendulum.py")
    forced = load_model(MODELS_DIR / "cart_pendulum_forced.py")
    assert (str(plain.T), str(plain.V)) == (str(forced.T), str(forced.V))
    M, m, l, k, g = 1.0, 0.5, 1.0, 10.0, 9.81
    A, B, C, D = lg.linearize(generated("cart_pendulum_forced"), [0.0, 0.0], [0.0, 0.0], u=[0.0])
    H = np.array([[M + m, m * l], [m * l, m * l**2]])
    lower = -np.linalg.solve(H, np.diag([k, m * g * l]))
    np.testing.assert_allclose(A, np.block([[np.zeros((2, 2)), np.eye(2)],
                                            [lower, np.zeros((2, 2))]]), atol=1e-13)
    np.testing.assert_allclose(B, [[0], [0], [1 / M], [-1 / (M * l)]], atol=1e-14)
