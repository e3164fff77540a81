"""The GPU ensemble (lagrange_gen.ensemble(..., device="cuda"), lagrange_gen.gpu) equals the CPU
ensemble member by member: every saved row, the energy and Newton statistics, the status,
steps, time and state where a member stopped, and its failure message. Under numba's CUDA
simulator (tests/gpu/conftest.py) the member function runs compiled for the CPU, so the two
agree to the last bit; on a GPU they differ by round-off (fused multiply-adds), which the
tolerances allow. A few members and steps each: the time is compile time."""

import math
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("numba_cuda", reason="numba-cuda is not installed (the gpu or test extra)")

import lagrange_gen as lg                                       # noqa: E402
from lagrange_gen.errors import SimulationError                 # noqa: E402
from lagrange_gen.steppers.core import registry, status         # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
CART = str(ROOT / "generated" / "cart_pendulum.py")
DRIVEN = str(ROOT / "generated" / "driven_pendulum.py")

#: On a GPU: fused multiply-adds round differently from the CPU's separate ones.
RTOL, ATOL = 1e-12, 1e-13


def _cart_members(M=3, seed=1):
    rng = np.random.default_rng(seed)
    return dict(q0=rng.uniform(-0.5, 0.5, (M, 2)), v0=rng.uniform(-1.0, 1.0, (M, 2)),
                params={"k": rng.uniform(5.0, 15.0, M)})


def _assert_same(gpu, cpu, rtol=RTOL, atol=ATOL):
    """Every output of two EnsembleResults of the same members agrees (NaN where the other
    has NaN: the rows after a failure)."""
    assert gpu.status.tolist() == cpu.status.tolist()
    assert gpu.steps_done.tolist() == cpu.steps_done.tolist()
    assert gpu.messages == cpu.messages
    np.testing.assert_array_equal(gpu.t, cpu.t)
    for name in ("q", "v", "energy", "newton_iters", "newton_residual", "fail_time",
                 "fail_state"):
        np.testing.assert_allclose(getattr(gpu, name), getattr(cpu, name), rtol=rtol,
                                   atol=atol, equal_nan=True, err_msg=name)


#: The GPU methods for models without constraints, elements or contacts.
PLAIN_METHODS = tuple(m for m in registry.GPU_METHODS if not registry.inapplicable(m, 0, 0))


#: Run by default: the explicit Runge-Kutta core, and the Newton with its dense LU in a
#: symmetric and a damping method; --thorough runs every one (each lowers for the CUDA target
#: by default or with --thorough, test_gpu_environment.py).
PLAIN_BY_DEFAULT = ("rk4", "midpoint", "implicit_euler")


@pytest.mark.parametrize("method", PLAIN_METHODS)
def test_members_equal_the_cpu_ensemble(method, request):
    """Each GPU method on the cart pendulum: 3 members (their own q0, v0 and k), 11 steps saved
    every 4th (so the last row is the final state, written after the loop)."""
    if method not in PLAIN_BY_DEFAULT and not request.config.getoption("thorough",
                                                                       default=False):
        pytest.skip("--thorough runs every method of PLAIN_METHODS")
    run = dict(_cart_members(), t_end=0.011, h=1e-3, save_every=4)
    cpu = lg.ensemble(CART, method, **run)
    gpu = lg.ensemble(CART, method, device="cuda", **run)
    assert gpu.device != "cpu" and cpu.device == "cpu"
    assert gpu.q.shape == cpu.q.shape == (3, 4, 2)
    assert gpu.ok.all()
    _assert_same(gpu, cpu)


CARTESIAN = str(ROOT / "generated" / "cartesian_pendulum.py")

#: The other GPU methods, each on a model it applies to: (generated module, members' q0, v0).
#: The default profile runs a constrained and a contact method (the simulator's run is slow:
#: about a minute each); --thorough runs every one.
KINDS = {
    # holonomic constraints: a consistent start (|r| = 1, r . v = 0) for each member
    "rattle": (CARTESIAN, [[0.6, -0.8], [0.8, -0.6]], [[0.8, 0.6], [0.3, 0.4]]),
    "constrained_midpoint": (CARTESIAN, [[0.6, -0.8], [0.8, -0.6]], [[0.8, 0.6], [0.3, 0.4]]),
    "constrained_implicit_euler": (CARTESIAN, [[0.6, -0.8]], [[0.8, 0.6]]),
    "spook": (CARTESIAN, [[0.6, -0.8]], [[0.8, 0.6]]),
    "index1": (CARTESIAN, [[0.6, -0.8]], [[0.8, 0.6]]),
    # a dry-friction element: members that stick and that slip
    "nonsmooth_euler": (str(ROOT / "generated" / "coulomb_oscillator.py"), [[0.05], [1.0]],
                        [[0.0], [0.0]]),
    # a unilateral contact: members that hit the floor within the run and one that does not
    "moreau_jean": (str(ROOT / "generated" / "bouncing_ball.py"), [[1e-3], [2e-3], [1.0]],
                    [[-1.0], [-0.5], [0.0]]),
    # contacts with a holonomic constraint: a pendulum on a rod hitting the wall x = 0.5 within
    # the run (it starts 1e-3 from it) and one that does not
    "spook_contacts": (str(ROOT / "generated" / "pendulum_wall_cartesian.py"),
                       [[0.499, -math.sqrt(1 - 0.499**2)], [0.0, -1.0]],
                       [[math.sqrt(1 - 0.499**2), 0.499], [0.0, 0.0]]),
    # velocity constraints
    "nonholonomic_rk4": (str(ROOT / "generated" / "chaplygin_sleigh.py"), None, None),
}
BY_DEFAULT = ("rattle", "moreau_jean")


def test_every_gpu_method_is_tested():
    assert set(PLAIN_METHODS) | set(KINDS) == set(registry.GPU_METHODS)


@pytest.mark.parametrize("method", sorted(KINDS))
def test_constrained_nonsmooth_and_contact_members_equal_the_cpu(method, request):
    """The methods with constraints, elements, contacts or velocity constraints: what they save
    besides q and v (multipliers, residuals, contact impulses, element states) travels through
    the member's out_extra, so EnsembleResult.saved is compared too."""
    if method not in BY_DEFAULT and not request.config.getoption("thorough", default=False):
        pytest.skip("--thorough runs every method of KINDS")
    path, q0, v0 = KINDS[method]
    run = dict(t_end=0.006, h=1e-3, save_every=2)
    if q0 is not None:
        run.update(q0=q0, v0=v0)
    cpu = lg.ensemble(path, method, **run)
    gpu = lg.ensemble(path, method, device="cuda", **run)
    assert gpu.device != "cpu" and cpu.ok.all()
    _assert_same(gpu, cpu)
    assert sorted(gpu.saved) == sorted(cpu.saved) and cpu.saved
    for name in cpu.saved:
        np.testing.assert_allclose(gpu.saved[name], cpu.saved[name], rtol=RTOL, atol=ATOL,
                                   equal_nan=True, err_msg=name)


def test_a_model_with_work_and_transport():
    """driven_pendulum (rheonomic: T1 = b(q, t) . v, and the run loop integrates the work):
    midpoint's Newton with the transport terms, and the work path of run_loop.steps."""
    run = dict(q0=[[0.3], [-0.2]], v0=[[0.0], [0.5]], params={"w": [50.0, 80.0]},
               t_end=0.006, h=1e-3, save_every=2)
    _assert_same(lg.ensemble(DRIVEN, "midpoint", device="cuda", **run),
                 lg.ensemble(DRIVEN, "midpoint", **run))


def test_a_member_that_blows_up_stops_alone():
    """explicit Euler with a blow-up bound that member 1 (fast) passes: UNSTABLE, its step,
    time, state and message as on the CPU, NaN rows after it; the others finish."""
    run = dict(q0=[[0.1, 0.1], [0.1, 0.1], [0.0, 0.2]], v0=[[0.0, 0.0], [3.0, 4.0], [0.0, 0.0]],
               t_end=0.05, h=1e-2, save_every=1, blowup_bound=3.5)
    cpu = lg.ensemble(CART, "explicit_euler", **run)
    gpu = lg.ensemble(CART, "explicit_euler", device="cuda", **run)
    assert gpu.status.tolist() == [status.OK, status.UNSTABLE, status.OK]
    assert np.isnan(gpu.q[1, -1]).all() and not np.isnan(gpu.q[0]).any()
    assert len(gpu.failures()) == 1 and gpu.failures()[0].startswith("member 1: ")
    _assert_same(gpu, cpu)


def test_newton_failure_status_and_message():
    """implicit Euler allowed one Newton iteration at a tolerance it cannot reach: every member
    fails in its first step with the CPU's status and one-line message."""
    run = dict(_cart_members(2), t_end=0.004, h=1e-3, max_iter=1, newton_tol=1e-15)
    cpu = lg.ensemble(CART, "implicit_euler", **run)
    gpu = lg.ensemble(CART, "implicit_euler", device="cuda", **run)
    assert set(gpu.status.tolist()) == {status.NEWTON_DIVERGED}
    assert all("\n" not in line for line in gpu.failures())
    _assert_same(gpu, cpu)


def test_float32_members_are_close_to_float64():
    """dtype="float32": state, parameters and outputs in float32, returned as float64; rk4 over
    20 steps stays within float32 round-off of the float64 run."""
    run = dict(_cart_members(), t_end=0.02, h=1e-3, save_every=5)
    single = lg.ensemble(CART, "rk4", device="cuda", dtype="float32", **run)
    double = lg.ensemble(CART, "rk4", **run)
    assert single.jit == "cuda float32" and single.q.dtype == np.float64
    assert single.ok.all()
    np.testing.assert_allclose(single.q, double.q, rtol=1e-5, atol=1e-6)
    assert np.abs(single.q - double.q).max() > 0      # float32 indeed (not float64 again)


@pytest.mark.parametrize("kwargs, message", [
    (dict(method="composition"), "method 'composition' does not run on the GPU yet; "
                                 "device='cuda' runs explicit_euler, symplectic_euler"),
    (dict(method="rk4", dtype="float16"), "dtype 'float16': device='cuda' runs float64 or "
                                          "float32"),
    (dict(method="midpoint", dtype="float32"), "newton_tol=1e-12 is below what float32"),
    (dict(method="rk4", device="tpu"), "device 'tpu': expected 'cpu' or 'cuda'"),
    (dict(method="rk4", device="cpu", dtype="float32"), "dtype 'float32' runs on "
                                                        "device='cuda' only"),
    (dict(method="rk4", client=object()), "pass no Dask client"),
])
def test_refusals_are_one_line(kwargs, message):
    kwargs = {"device": "cuda", **kwargs}
    method = kwargs.pop("method")
    with pytest.raises(SimulationError) as caught:
        lg.ensemble(CART, method, q0=[0.1, 0.2], t_end=0.002, h=1e-3, **kwargs)
    assert message in str(caught.value) and "\n" not in str(caught.value)


def test_a_model_with_events_is_refused():
    from types import SimpleNamespace

    from lagrange_gen.gpu.member_source import refusal
    model = SimpleNamespace(NAME="bouncing", N_EVENTS=1)
    assert refusal(model, "rk4") == ("bouncing: events are not located on the GPU yet (the "
                                     "model has 1); use device='cpu'")
    assert refusal(SimpleNamespace(NAME="plain", N_EVENTS=0), "rk4") == ""


def test_bench_gpu_measures_and_reports():
    """`lagrange-gen bench gpu`'s measurement and report on 2 members and 3 steps (here the
    simulator's figures: the bench itself refuses to report the simulator as a GPU)."""
    from lagrange_gen.bench.gpu import measure, report_lines
    row = measure(lg.import_generated(CART), 2, n_steps=3)
    assert row["failed"] == row["cpu_failed"] == 0
    assert row["diff"] <= 1e-13 and 0 < row["f32_diff"] < 1e-5
    lines = report_lines([("cart pendulum", row)], "test device")
    assert lines[6].startswith("| cart pendulum | 2 | ") and "GPU: test device." in lines[2]
    assert lines[-1] == "Every member of every run reached t_end."
