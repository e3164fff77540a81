"""lagrange_gen.ensemble: members equal simulate() member by member (bitwise: the same run_loop
on the same inputs, one chunk), failing members reported without losing the others, input and
memory errors as one line, and the same results on 1 and 2 threads."""

from pathlib import Path

import numba
import numpy as np
import pytest

import lagrange_gen as lg
from lagrange_gen.codegen import generate_model
from lagrange_gen.errors import LagrangeGenError, SimulationError
from lagrange_gen.run import checks as run_checks
from lagrange_gen.run.loader import import_generated
from lagrange_gen.steppers.core import status

MODELS = Path(__file__).resolve().parents[2] / "models"


@pytest.fixture(scope="module")
def cart(tmp_path_factory):
    out = tmp_path_factory.mktemp("ensemble_gen")
    result = generate_model(MODELS / "cart_pendulum.py", out,
                            methods=["rk4", "midpoint", "explicit_euler"])
    return import_generated(result.path)


@pytest.fixture(scope="module")
def cartesian(tmp_path_factory):
    out = tmp_path_factory.mktemp("ensemble_gen_constrained")
    result = generate_model(MODELS / "cartesian_pendulum.py", out, methods=["rattle", "index1"])
    return import_generated(result.path)


def _members(M, seed=0):
    rng = np.random.default_rng(seed)
    return (rng.uniform(-0.8, 0.8, (M, 2)), rng.uniform(-1.0, 1.0, (M, 2)),
            rng.uniform(5.0, 15.0, M), rng.uniform(0.2, 1.0, M))


def _assert_member_equals(ens, i, traj):
    """Member i of the ensemble and a Trajectory: bitwise equal times, states, energies and
    Newton statistics (the same jitted loop on the same numbers)."""
    np.testing.assert_array_equal(ens.t, traj.t)
    np.testing.assert_array_equal(ens.q[i], traj.q)
    np.testing.assert_array_equal(ens.v[i], traj.v)
    np.testing.assert_array_equal(ens.energy[i], traj.energy)
    np.testing.assert_array_equal(ens.newton_iters[i], traj.newton_iters)
    for name, values in traj.saved.items():
        np.testing.assert_array_equal(ens.saved[name][i], values)


@pytest.mark.parametrize("method", ["rk4", "midpoint"])
def test_members_equal_simulate_bitwise(cart, method):
    M = 210
    q0, v0, k, m = _members(M)
    # 100 steps, save_every 7: the final state gets its own row, as in simulate
    ens = lg.ensemble(cart, method, q0=q0, v0=v0, params={"k": k, "m": m, "g": 9.8},
                      t_end=1.0, h=0.01, save_every=7)
    assert ens.q.shape == (M, 100 // 7 + 2, 2) and ens.energy.shape == (M, 16)
    assert ens.ok.all() and ens.failures() == [] and (ens.steps_done == 100).all()
    np.testing.assert_array_equal(ens.params[:, cart.PARAMS.index("k")], k)
    for i in range(M):
        traj = lg.simulate(cart, method, q0[i], v0[i], params={"k": k[i], "m": m[i], "g": 9.8},
                           t_end=1.0, h=0.01, save_every=7)
        _assert_member_equals(ens, i, traj)


def test_constrained_members_equal_simulate(cartesian):
    M = 12
    angle = np.linspace(-1.2, 1.2, M)
    length = np.linspace(0.5, 2.0, M)
    # off the circle by 1 %: each member is projected, as simulate projects it
    q0 = 1.01 * np.stack([length * np.sin(angle), -length * np.cos(angle)], axis=1)
    v0 = np.stack([np.cos(angle), np.sin(angle)], axis=1)
    with pytest.warns(UserWarning, match=f"{M} of {M} members was projected"):
        ens = lg.ensemble(cartesian, "rattle", q0=q0, v0=v0, params={"l": length}, t_end=0.5,
                          h=0.01, save_every=4)
    assert ens.ok.all() and set(ens.saved) == {"multipliers", "constraint_error",
                                               "velocity_constraint_error"}
    for i in range(M):
        with pytest.warns(UserWarning):
            traj = lg.simulate(cartesian, "rattle", q0[i], v0[i], params={"l": length[i]},
                               t_end=0.5, h=0.01, save_every=4)
        _assert_member_equals(ens, i, traj)
    assert np.abs(ens.saved["constraint_error"]).max() < 1e-10


def test_a_tuple_setting_reaches_every_member(cartesian):
    """index1's baumgarte = (alpha, beta) is a tuple inside the settings record, which numba's
    parallel loop cannot pass to its body as it is: each member equals simulate with the same
    gains, and the gains act (the constraint drifts less than without them)."""
    M = 3
    angle = np.linspace(-0.8, 0.8, M)
    q0 = np.stack([np.sin(angle), -np.cos(angle)], axis=1)
    v0 = np.stack([np.cos(angle), np.sin(angle)], axis=1)
    run = dict(q0=q0, v0=v0, t_end=1.0, h=0.01, save_every=10)
    ens = lg.ensemble(cartesian, "index1", baumgarte=(10.0, 10.0), **run)
    free = lg.ensemble(cartesian, "index1", **run)
    assert ens.ok.all()
    for i in range(M):
        traj = lg.simulate(cartesian, "index1", q0[i], v0[i], t_end=1.0, h=0.01, save_every=10,
                           baumgarte=(10.0, 10.0))
        _assert_member_equals(ens, i, traj)
    stabilized = np.abs(ens.saved["constraint_error"][:, -1]).max()
    assert stabilized < 0.5 * np.abs(free.saved["constraint_error"][:, -1]).max()


def test_members_with_a_nonsmooth_element_equal_simulate(tmp_path_factory):
    """The Coulomb oscillator (a DryFriction element: nonsmooth_euler runs for implicit_euler):
    the element's state starts at 0 in every member as in simulate (an ensemble's outputs are
    NaN until written, and row 0 of the saved fields is the method's initial state), members
    that slide and one that sticks from the start."""
    out = tmp_path_factory.mktemp("ensemble_gen_friction")
    mod = import_generated(generate_model(MODELS / "coulomb_oscillator.py", out,
                                          methods=["nonsmooth_euler"]).path)
    q0 = np.array([[1.05], [0.5], [0.05]])
    ens = lg.ensemble(mod, "implicit_euler", q0=q0, t_end=0.5, h=1e-3, save_every=50)
    assert ens.ok.all() and ens.method == "nonsmooth_euler"
    for i in range(3):
        traj = lg.simulate(mod, "implicit_euler", q0[i], t_end=0.5, h=1e-3, save_every=50)
        _assert_member_equals(ens, i, traj)
    # |k x0| = 0.05 <= F_d = 0.1: the third member never moves
    assert (ens.q[2] == 0.05).all()


@pytest.mark.filterwarnings("ignore::lagrange_gen.EnergyWarning")
def test_failing_member_reported_others_finish(cart):
    q0, v0, k, _ = _members(8, seed=1)
    v0[3] = [0.0, 40.0]                     # explicit Euler spins this one past the bound
    settings = dict(blowup_bound=60.0)
    ens = lg.ensemble(cart, "explicit_euler", q0=q0, v0=v0, params={"k": k}, t_end=2.0,
                      h=0.01, **settings)
    assert ens.status.tolist() == [0, 0, 0, status.UNSTABLE, 0, 0, 0, 0]
    with pytest.raises(lg.BlowUp) as raised:
        lg.simulate(cart, "explicit_euler", q0[3], v0[3], params={"k": k[3]}, t_end=2.0,
                    h=0.01, **settings)
    failure = raised.value
    assert ens.failures() == [f"member 3: {failure}"]
    assert ens.steps_done[3] == failure.step - 1 and ens.fail_time[3] == failure.time
    np.testing.assert_array_equal(ens.fail_state[3], failure.state)
    row = failure.step // 1                 # rows after the failing step are NaN
    assert np.isnan(ens.q[3, row:]).all() and np.isfinite(ens.q[3, :row]).all()
    for i in (0, 4, 7):
        traj = lg.simulate(cart, "explicit_euler", q0[i], v0[i], params={"k": k[i]},
                           t_end=2.0, h=0.01, **settings)
        _assert_member_equals(ens, i, traj)


def test_grid_is_the_cartesian_product(cart):
    g = lg.grid(k=[1.0, 2.0, 3.0], m=[0.5, 0.7])
    assert g["k"].tolist() == [1, 1, 2, 2, 3, 3] and g["m"].tolist() == [0.5, 0.7] * 3
    ens = lg.ensemble(cart, "rk4", q0=[0.1, 0.2], params=g, t_end=0.05, h=0.01)
    assert ens.q.shape == (6, 6, 2)
    np.testing.assert_array_equal(ens.params[:, cart.PARAMS.index("m")], g["m"])


@pytest.mark.parametrize("kwargs, message", [
    (dict(q0=np.zeros((3, 2)), params={"k": np.ones(4)}),
     r"disagree on the member count: q0 has 3, params\['k'\] has 4"),
    (dict(q0=np.zeros((3, 3))), r"q0 has shape \(3, 3\); expected \(2,\) or \(M, 2\)"),
    (dict(v0=[[0, 0], [np.nan, 0]]), r"v0 contains a non-finite value \(member 1\)"),
    (dict(params={"k": [1.0, np.inf]}), r"params\['k'\] is not finite for member 1"),
    (dict(params={"stiffness": [1.0, 2.0]}), "unknown parameter 'stiffness'"),
    (dict(params=np.ones((2, 3))), r"params has shape \(2, 3\); expected \(M, 5\)"),
])
def test_input_errors_are_one_line(cart, kwargs, message):
    with pytest.raises(SimulationError, match=message) as raised:
        lg.ensemble(cart, "rk4", t_end=0.1, h=0.01, **kwargs)
    assert "\n" not in str(raised.value)


def test_adaptive_method_refused(cart):
    with pytest.raises(SimulationError, match="fixed-step methods only") as raised:
        lg.ensemble(cart, "dop853", q0=np.zeros((2, 2)), t_end=0.1, h=0.01)
    assert "\n" not in str(raised.value)


def test_memory_refusal_says_what_it_needs(cart, monkeypatch):
    monkeypatch.setattr(run_checks, "available_memory", lambda: 10**6)
    # 1000 members x 1001 rows x (2 n + 4 stats (energy, iterations, residual, work) + 3 copies)
    # x 8 bytes = 88 MB, and 1000 members x (2 n + 5 parameters) x 8 bytes of inputs
    with pytest.raises(SimulationError, match=r"1000 members saving 1001 states each needs "
                       r"0\.0882 GB of memory and 0\.001 GB is available; use save_every >= "
                       r"177") as raised:
        lg.ensemble(cart, "rk4", q0=np.zeros((1000, 2)), t_end=10.0, h=0.01)
    assert "\n" not in str(raised.value)


def test_one_and_two_threads_give_identical_results(cart):
    q0, v0, k, m = _members(64, seed=2)
    runs = []
    before = numba.get_num_threads()
    try:
        for threads in (1, 2):
            numba.set_num_threads(threads)
            runs.append(lg.ensemble(cart, "midpoint", q0=q0, v0=v0, params={"k": k, "m": m},
                                    t_end=0.5, h=0.01, save_every=5, progress=True))
    finally:
        numba.set_num_threads(before)
    one, two = runs
    for name in ("q", "v", "energy", "newton_iters", "status", "steps_done"):
        np.testing.assert_array_equal(getattr(one, name), getattr(two, name))
