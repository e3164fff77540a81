"""Identities every model in models/ must satisfy at random states (they cannot be faked)."""

import numpy as np
import pytest
import sympy as sp

from lg_test_support import MODEL_FILES, ROBOT_MODELS

STEMS = [f.stem for f in MODEL_FILES if f.stem not in ROBOT_MODELS]
#: The Christoffel form differentiates H once more in plain sympy; on the bicycle's expanded
#: 8 x 8 H that is over a minute, and its H, h and linearization are checked against the
#: published benchmark (tests/rolling/test_bicycle_benchmark.py).
CHRISTOFFEL_STEMS = [stem for stem in STEMS if stem != "bicycle"]


def random_state(rng, n):
    """q with every |q_i| in [0.3, 1.5] (either sign), qd in [-1.5, 1.5]. The models' coordinate
    singularities sit at q_i = 0 (Kepler's and the central field's r = 0, the top's theta = 0,
    where H is singular) and none lies within 1.5 of the origin otherwise."""
    sign = rng.choice([-1.0, 1.0], n)
    return sign * rng.uniform(0.3, 1.5, n), rng.uniform(-1.5, 1.5, n)


@pytest.mark.parametrize("stem", STEMS)
def test_mass_matrix_symmetric_positive_definite(generated, stem):
    mod = generated(stem)
    rng = np.random.default_rng(3)
    H = np.empty((mod.N_COORDS, mod.N_COORDS))
    for _ in range(50):
        q, _ = random_state(rng, mod.N_COORDS)
        mod.mass_matrix(q, 0.0, mod.DEFAULT_PARAMS, H)
        np.testing.assert_array_equal(H, H.T)
        assert np.linalg.eigvalsh(H).min() > 0


@pytest.mark.parametrize("stem", STEMS)
def test_energy_rate_equals_power_of_nonconservative_forces(generated, derived, stem):
    """dE/dt along the flow (central difference of the energy kernel, E = T2 - T0 + V) =
    qd . Q_nc - dL/dt (the explicit time derivative of L = T - V), where qdd comes from forward
    dynamics and Q_nc = forces - dD/dqd. For conservative scleronomic models dE/dt = 0."""
    mod, dyn = generated(stem), derived(stem)
    args = [dyn.q, dyn.qd, dyn.t, dyn.params]
    model = dyn.model
    Q_nc = [f - sp.diff(model.dissipation, v) for f, v in zip(model.forces, dyn.qd)]
    power = sp.lambdify(args, sum(v * Qj for v, Qj in zip(dyn.qd, Q_nc))
                        - sp.diff(model.T - model.V, dyn.t))
    rng = np.random.default_rng(4)
    p = mod.DEFAULT_PARAMS
    eps = 1e-5
    for _ in range(20):
        q, qd = random_state(rng, mod.N_COORDS)
        t = rng.uniform(0, 5)
        qdd = mod.accelerations(q, qd, t, p)
        e_plus = mod.energy(q + eps * qd, qd + eps * qdd, t + eps, p)
        e_minus = mod.energy(q - eps * qd, qd - eps * qdd, t - eps, p)
        dEdt = (e_plus - e_minus) / (2 * eps)
        want = power(q, qd, t, p)
        scale = 1 + abs(mod.energy(q, qd, t, p)) + abs(want)    # the driven pendulum: |dE/dt| ~ 1e3
        assert abs(dEdt - want) < 1e-5 * scale


def christoffel_C(dyn):
    """C_jk = sum_i 1/2 (dH_jk/dq_i + dH_ji/dq_k - dH_ik/dq_j) qd_i, written independently of derive."""
    n, H, q, qd = dyn.n, dyn.H, dyn.q, dyn.qd
    return sp.Matrix(n, n, lambda j, k: sum(
        (sp.diff(H[j, k], q[i]) + sp.diff(H[j, i], q[k]) - sp.diff(H[i, k], q[j])) * qd[i] / 2
        for i in range(n)))


@pytest.mark.parametrize("stem", CHRISTOFFEL_STEMS)
def test_christoffel_form_and_skew_symmetry(derived, stem):
    """h = C(q, qd) qd with Christoffel C, and Hdot - 2C is skew-symmetric."""
    dyn = derived(stem)
    C = christoffel_C(dyn)
    Hdot = sum((dyn.H.diff(qi) * qdi for qi, qdi in zip(dyn.q, dyn.qd)), sp.zeros(dyn.n, dyn.n))
    args = [dyn.q, dyn.qd, dyn.params]
    f_h = sp.lambdify(args, dyn.h)
    f_Cqd = sp.lambdify(args, C * sp.Matrix(dyn.qd))
    f_N = sp.lambdify(args, Hdot - 2 * C)
    rng = np.random.default_rng(5)
    p = [1.0 if d is None else d for d in dyn.model.defaults()]
    for _ in range(20):
        q, qd = random_state(rng, dyn.n)
        np.testing.assert_allclose(np.ravel(f_h(q, qd, p)), np.ravel(f_Cqd(q, qd, p)), atol=1e-12)
        N = np.asarray(f_N(q, qd, p), dtype=float)
        np.testing.assert_allclose(N + N.T, 0.0, atol=1e-12)
