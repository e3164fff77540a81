"""Bad input and failures: routing refusals, redundant and unsatisfiable constraints, projection of
inconsistent initial conditions with a warning, Newton failure with step and residual."""

import numpy as np
import pytest

from constraint_util import generated_model, pendulum_state
from lagrange_gen.errors import NewtonDivergence, SimulationError
from lagrange_gen.run.consistent import ConstraintError, consistent_initial_state
from lagrange_gen.run.simulate import simulate


def test_unconstrained_method_on_constrained_model_is_refused():
    mod = generated_model("cartesian_pendulum")
    with pytest.raises(SimulationError, match=r"'verlet' ignores the model's constraints "
                                              r"\(constraint 0 \(x\*\*2/2.*rattle, "
                                              r"constrained_midpoint, constrained_implicit_euler"):
        simulate(mod, "verlet", [0.0, -1.0], t_end=1.0, h=1e-3)


def test_constrained_method_on_unconstrained_model_is_refused():
    mod = generated_model("stretchable_pendulum")
    with pytest.raises(SimulationError, match="'rattle' is for models with constraints"):
        simulate(mod, "rattle", [0.0, -1.0], t_end=1.0, h=1e-3)


def test_redundant_constraints_are_named():
    mod = generated_model("redundant_pendulum")
    with pytest.raises(ConstraintError, match=r"redundant or degenerate constraints at q0 \(rank "
                                              r"of J = 1 < 2\): constraint 0 \(.*\); constraint 1"):
        simulate(mod, "rattle", [0.0, -1.0], t_end=1.0, h=1e-3)


def test_unsatisfiable_constraint_is_reported():
    mod = generated_model("imaginary_circle")
    with pytest.raises(ConstraintError, match=r"cannot be satisfied from q0 = \[0.5, -0.5\].*"
                                              r"max\|Phi\| = 1"):
        simulate(mod, "rattle", [0.5, -0.5], t_end=1.0, h=1e-3)


def test_inconsistent_initial_state_is_projected_with_a_warning():
    mod = generated_model("cartesian_pendulum")
    q_off, v_off = np.array([0.6, -0.9]), np.array([1.0, 1.0])     # |q| = 1.08, v not tangent
    with pytest.warns(UserWarning) as record:
        traj = simulate(mod, "rattle", q_off, v_off, t_end=0.01, h=1e-3)
    messages = [str(w.message) for w in record]
    assert any("q0 violates the constraints by max|Phi| = 0.085" in m and "moving q0 by" in m
               for m in messages), messages
    assert any("v0 is not tangent" in m and "max|J v0| = 0.277" in m for m in messages), messages
    assert abs(np.hypot(*traj.q[0]) - 1.0) < 1e-14
    assert abs(traj.q[0] @ traj.v[0]) < 1e-14
    assert traj.constraint_error[0] < 1e-15 and traj.velocity_constraint_error[0] < 1e-15
    # The projection is the closest point: along the radius for the pendulum.
    assert np.allclose(traj.q[0], q_off / np.hypot(*q_off), atol=1e-14)


def test_consistent_state_gives_no_warning_and_exact_multiplier():
    mod = generated_model("cartesian_pendulum")
    q0, v0 = pendulum_state(0.0, 2.0)          # bottom, omega = 2: tension m (g + l omega^2)
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        state = consistent_initial_state(mod, q0, v0, np.array(mod.DEFAULTS))
    # J^T lam = lam q is the force on the bob: lam q_y = -lam = m (g + l omega^2) upwards.
    assert state.lam[0] == pytest.approx(-(9.81 + 4.0), rel=1e-14)


def test_newton_failure_names_step_and_residual():
    """A step far too large for one Newton iteration: NewtonDivergence at step 1 with the
    residual (max |Phi| of the last iterate) in the exception and its message."""
    mod = generated_model("cartesian_pendulum")
    q0, v0 = pendulum_state(1.0, 3.0)
    expected = r"rattle: step 1 of 2 \(t = 0, h = 0.5\): Newton did not converge in 1 iterations "
    with pytest.raises(NewtonDivergence, match=expected + r"\(residual ") as info:
        simulate(mod, "rattle", q0, v0, t_end=1.0, h=0.5, max_iter=1)
    assert info.value.step == 1 and info.value.time == 0.0 and info.value.residual > 1e-3


def test_spook_settings_are_checked():
    mod = generated_model("cartesian_pendulum")
    with pytest.raises(SimulationError, match="compliance must be a finite number >= 0"):
        simulate(mod, "spook", [0.0, -1.0], t_end=0.01, h=1e-3, compliance=-1.0)
    with pytest.raises(SimulationError, match="relaxation must be a finite number > 0"):
        simulate(mod, "spook", [0.0, -1.0], t_end=0.01, h=1e-3, relaxation=0.0)


def test_trajectory_outputs(tmp_path):
    """Multipliers (S, m), |Phi| and |J v| per saved row, also in the npz file; chunked runs
    carry the multiplier across chunk boundaries (same result as one chunk)."""
    import lagrange_gen.run.fixed_driver as sim       # where the chunk size lives
    mod = generated_model("cartesian_double_pendulum")
    q0 = np.array([0.0, -1.0, 0.0, -2.0])
    v0 = np.array([1.0, 0.0, 2.5, 0.0])
    traj = simulate(mod, "rattle", q0, v0, t_end=1.0, h=1e-3, save_every=7)
    assert traj.multipliers.shape == (len(traj.t), 2)
    assert traj.constraint_names == tuple(mod.CONSTRAINTS)
    assert traj.constraint_error.shape == traj.velocity_constraint_error.shape == traj.t.shape
    traj.to_npz(tmp_path / "t.npz")
    traj.to_csv(tmp_path / "t.csv")
    csv = np.loadtxt(tmp_path / "t.csv", delimiter=",", skiprows=1)
    assert np.array_equal(csv[:, -4:-2], traj.multipliers)
    data = np.load(tmp_path / "t.npz")
    assert np.array_equal(data["multipliers"], traj.multipliers)
    old = sim.CHUNK_STEPS
    try:
        sim.CHUNK_STEPS = 50
        chunked = simulate(mod, "rattle", q0, v0, t_end=1.0, h=1e-3, save_every=7)
    finally:
        sim.CHUNK_STEPS = old
    assert np.array_equal(chunked.q, traj.q)
    assert np.array_equal(chunked.multipliers, traj.multipliers)


def test_singular_newton_matrix_is_diagnosed_by_constraint():
    """What simulate appends to a SingularMass raised by a constrained method: the dependent
    constraints at the failing state, by index and equation."""
    from lagrange_gen.run.consistent import diagnose_singular
    mod = generated_model("redundant_pendulum")
    text = diagnose_singular(mod, np.array([0.0, -1.0]), np.array(mod.DEFAULTS))
    assert "linearly dependent" in text and "constraint 0 (" in text and "constraint 1 (" in text
    assert diagnose_singular(generated_model("cartesian_pendulum"), np.array([0.0, -1.0]),
                             np.array([1.0, 1.0, 9.81])) == ""


SHRINKING = '''from lagrange_gen import Model, coordinates, parameters, t
x, y = coordinates("x y")
m, g = parameters("m g", defaults=(1.0, 9.81))
model = Model("shrink", coords=[x, y], T=m * (x.d**2 + y.d**2) / 2, V=m * g * y,
              constraints=[x**2 + y**2 - (1 - t)])
'''


def test_infeasible_rheonomic_constraint_warns(tmp_path):
    """x^2 + y^2 = 1 - t has no solution past t = 1: spook ended with max|Phi| = 6.3 and no word
    (issue 34, item 8)."""
    path = tmp_path / "shrink.py"
    path.write_text(SHRINKING)
    with pytest.warns(UserWarning, match=r"max\|Phi\| = \d.*may have no solution"):
        traj = simulate(path, "spook", [1.0, 0.0], [-0.5, 0.0], t_end=2.0, h=0.01,
                        out_dir=tmp_path / "gen")
    assert any("max|Phi|" in w for w in traj.warnings)


def test_a_good_constrained_run_does_not_warn(tmp_path):
    import warnings
    path = tmp_path / "shrink.py"
    path.write_text(SHRINKING)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        simulate(path, "spook", [1.0, 0.0], [-0.5, 0.0], t_end=0.5, h=0.01, out_dir=tmp_path / "gen")
