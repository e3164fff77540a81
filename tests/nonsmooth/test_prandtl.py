"""Prandtl models through simulate(): HARD_CASES 9 and 10, the discrete identity, energy balance,
order of convergence, and identification from the simulated cycle."""

import numpy as np
import pytest

from lagrange_gen.identify import identify_prandtl
from lagrange_gen.analysis import nonsmooth_experiments as experiments
from lagrange_gen.run.simulate import simulate
from nonsmooth_util import forcing, ns_model  # noqa: F401  (fixture)


def restoring_force(traj, F, m, c):
    return experiments.restoring_force(traj.t, traj.v[:, 0], traj.h, F, m, c)


@pytest.fixture(scope="module")
def loop(ns_model):
    mod = ns_model("generalized_prandtl")
    traj = simulate(mod, method="implicit_euler", t_end=400.0, h=1e-2)
    return mod, traj


def test_discrete_identity_of_implicit_euler(loop):
    mod, traj = loop
    m, c, k0, f, omega = (traj.params[k] for k in ("m", "c", "k0", "f", "omega"))
    k = np.array([traj.params[f"k{i}"] for i in (1, 2, 3)])
    R = restoring_force(traj, forcing(traj, f, omega), m, c)
    internal = k0 * traj.q[1:, 0] + traj.element_state[1:] @ k
    np.testing.assert_allclose(R, internal, atol=1e-12 * max(1.0, np.abs(R).max()))
    eta = np.array([traj.params[f"eta{i}"] for i in (1, 2, 3)])
    assert np.all(np.abs(traj.element_state) <= eta * (1 + 1e-15))


def test_generalized_prandtl_loop_slopes_and_breakpoints(loop):
    """HARD_CASES 10: slopes 4/3, 1, 2/3, 1/3 (to 1e-9); breakpoints at 2, 4, 6 from the turn."""
    mod, traj = loop
    m, c, f, omega = (traj.params[k] for k in ("m", "c", "f", "omega"))
    R = np.concatenate([[np.nan], restoring_force(traj, forcing(traj, f, omega), m, c)])
    idx, x_turn = experiments.last_loading_branch(traj.q[:, 0], traj.v[:, 0])
    x, r = traj.q[idx, 0] - x_turn, R[idx]
    assert x.max() > 6.5, "the cycle must reach the last breakpoint"
    slopes, breaks = experiments.branch_slopes(x, r, [(0.2, 1.8), (2.2, 3.8), (4.2, 5.8), (6.2, x.max() - 0.1)])
    np.testing.assert_allclose(slopes, [4 / 3, 1.0, 2 / 3, 1 / 3], atol=1e-9, rtol=0)
    np.testing.assert_allclose(breaks, [2.0, 4.0, 6.0], atol=5e-3)


def test_identification_recovers_the_simulated_parameters(loop):
    """The identify package on our own simulated cycle (c known): k_i, eta_i within 1%."""
    mod, traj = loop
    m, c, f, omega = (traj.params[k] for k in ("m", "c", "f", "omega"))
    steady = traj.t[1:] > 150.0
    R = restoring_force(traj, forcing(traj, f, omega), m, c)
    fit = identify_prandtl(traj.q[1:, 0][steady], R[steady] + c * traj.v[1:, 0][steady],
                           n_elements=3, damping=c, velocity=traj.v[1:, 0][steady])
    np.testing.assert_allclose(fit.k, [1 / 3] * 3, rtol=1e-2)
    np.testing.assert_allclose(fit.eta, [1.0, 2.0, 3.0], rtol=1e-2)
    assert fit.k0 == pytest.approx(1 / 3, rel=1e-2)


def test_discrete_energy_balance_and_nonnegative_dissipation(ns_model):
    """Per step: dE = F dx - c v dx - k u+ (ds - du) - [m dv^2 + k0 dx^2 + k du^2]/2, with E
    including the element's elastic energy; plastic, viscous and numerical terms are >= 0."""
    mod = ns_model("viscoelastoplastic")
    traj = simulate(mod, method="implicit_euler", t_end=60.0, h=5e-3)
    P = traj.params
    m, c, k0, k1 = P["m"], P["c"], P["k0"], P["k1"]
    x, v, u = traj.q[:, 0], traj.v[:, 0], traj.element_state[:, 0]
    dx, dv, du = np.diff(x), np.diff(v), np.diff(u)
    F1 = forcing(traj, P["f"], P["omega"], "sin")[1:]
    plastic = k1 * u[1:] * (dx - du)
    viscous = c * v[1:] * dx
    numerical = 0.5 * (m * dv**2 + k0 * dx**2 + k1 * du**2)
    dE = np.diff(traj.energy)
    np.testing.assert_allclose(dE, F1 * dx - viscous - plastic - numerical, atol=1e-12)
    assert plastic.min() >= -1e-14 and plastic.sum() > 0.1      # it did yield, and dissipated
    assert viscous.min() >= 0 and numerical.min() >= 0


def test_convergence_order_about_one(ns_model):
    """Forced one-element model (Prandtl with hardening): fitted order in [0.85, 1.15]."""
    mod = ns_model("prandtl_hardening")
    T = 30.0
    ref = simulate(mod, method="implicit_euler", t_end=T, h=1e-4, save_every=10_000)
    hs = np.array([0.04, 0.02, 0.01, 0.005])
    errs = [abs(simulate(mod, method="implicit_euler", t_end=T, h=h).q[-1, 0] - ref.q[-1, 0]) for h in hs]
    order = np.polyfit(np.log(hs), np.log(errs), 1)[0]
    assert 0.85 <= order <= 1.15, (order, errs)


def test_prandtl_slip_phase_follows_the_lecture_closed_form(ns_model):
    """HARD_CASES 9, k0 = 0: during a slip phase (|u| = eta, epsilon fixed) the motion is
    x'' = (f cos(omega t) - epsilon k eta)/m, whose solution from the phase start is formula (6)
    of the lecture; excursions are of the order of 2 f/(m omega^2) = 400."""
    mod = ns_model("prandtl")
    traj = simulate(mod, method="implicit_euler", t_end=200.0, h=1e-3, save_every=10)
    P = traj.params
    f, w, k, eta, m = P["f"], P["omega"], P["k1"], P["eta"], P["m"]
    u = traj.element_state[:, 0]
    sliding = np.abs(np.abs(u) - eta) < 1e-12
    start = np.argmax(sliding & (traj.t > 20))
    stop = start + np.argmax(~sliding[start:])
    assert stop - start > 1000, "a long slip phase is expected"
    eps = np.sign(u[start])
    t0, x0, v0 = traj.t[start], traj.q[start, 0], traj.v[start, 0]
    tt = traj.t[start:stop] - t0
    exact = (f / (m * w**2) * (np.cos(w * t0) - np.cos(w * (t0 + tt))) - eps * k * eta / (2 * m) * tt**2
             + (v0 - f / (m * w) * np.sin(w * t0)) * tt + x0)
    excursion = np.ptp(traj.q[start:stop, 0])
    assert np.max(np.abs(traj.q[start:stop, 0] - exact)) < 1e-2 * excursion
    assert 100 < excursion < 800


def test_prandtl_with_hardening_sinusoidal_part(ns_model):
    """HARD_CASES 9, k0 = 1: in a slip phase x = A cos(omega t) + B sin(omega t) + D cos(omega0 t
    + phi) - epsilon k eta / k0 with A = f / (m (omega0^2 - omega^2)) ~ 2.02."""
    mod = ns_model("prandtl_hardening")
    traj = simulate(mod, method="implicit_euler", t_end=300.0, h=1e-3, save_every=10)
    P = traj.params
    f, w, k, eta, m, k0 = P["f"], P["omega"], P["k1"], P["eta"], P["m"], P["k0"]
    w0 = np.sqrt(k0 / m)
    u = traj.element_state[:, 0]
    sliding = np.abs(np.abs(u) - eta) < 1e-12
    start = np.argmax(sliding & (traj.t > 100))
    stop = start + np.argmax(~sliding[start:])
    t, x = traj.t[start:stop], traj.q[start:stop, 0]
    basis = np.column_stack([np.cos(w * t), np.sin(w * t), np.cos(w0 * t), np.sin(w0 * t), np.ones_like(t)])
    coef, *_ = np.linalg.lstsq(basis, x, rcond=None)
    assert coef[0] == pytest.approx(f / (m * (w0**2 - w**2)), rel=2e-2)
    assert coef[4] == pytest.approx(-np.sign(u[start]) * k * eta / k0, rel=2e-2)
