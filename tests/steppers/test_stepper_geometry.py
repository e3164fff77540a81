"""Geometric properties of the step maps: symmetry (time reversibility) and symplecticity in
(q, p = H(q) qdot), measured on the real compiled steppers."""

import numpy as np
import pytest

from stepper_util import mass_matrix, model, one_step, params  # model is a fixture
from lagrange_gen.steppers.core.registry import INFO, METHODS

# The fixed-step methods for smooth unconstrained models whose SPEC claims the property.
FIXED = [m for m in METHODS
         if not (INFO[m].constraints or INFO[m].elements or INFO[m].adaptive
                 or INFO[m].contacts or INFO[m].nonholonomic)]
SYMMETRIC = [m for m in FIXED if INFO[m].symmetric]
SYMPLECTIC = [m for m in FIXED if INFO[m].symplectic]
STATE = ([0.7, -0.4], [0.9, 1.3])          # generic state of the two-coordinate models


@pytest.mark.parametrize("name", ["double_pendulum", "cart_pendulum"])
@pytest.mark.parametrize("method", SYMMETRIC)
def test_symmetric_methods_retrace_their_step(model, name, method):
    """Phi_{-h} o Phi_h = identity; h is large so that a non-symmetric scheme cannot pass."""
    mod = model(name)
    p = params(mod)
    q0, v0 = (np.array(x) for x in STATE)
    h = 0.05
    q1, v1 = one_step(mod, method, q0, v0, h, p, t0=0.0)
    q2, v2 = one_step(mod, method, q1, v1, -h, p, t0=h)
    assert np.abs(q1 - q0).max() > 1e-2              # the step did move the state
    assert np.abs(np.concatenate([q2 - q0, v2 - v0])).max() < 1e-10


@pytest.mark.parametrize("method", ["explicit_euler", "implicit_euler", "symplectic_euler"])
def test_non_symmetric_methods_do_not_retrace(model, method):
    mod = model("double_pendulum")
    p = params(mod)
    q0, v0 = (np.array(x) for x in STATE)
    q1, v1 = one_step(mod, method, q0, v0, 0.05, p)
    q2, v2 = one_step(mod, method, q1, v1, -0.05, p, t0=0.05)
    assert np.abs(np.concatenate([q2 - q0, v2 - v0])).max() > 1e-4


def momentum_map(mod, method, h, p):
    """The step as a map of z = (q, p) with p = H(q) v: (2n,) -> (2n,)."""
    n = mod.N_COORDS

    def phi(z):
        q, mom = z[:n], z[n:]
        v = np.linalg.solve(mass_matrix(mod, q, p), mom)
        q1, v1 = one_step(mod, method, q, v, h, p)
        return np.concatenate([q1, mass_matrix(mod, q1, p) @ v1])
    return phi


def symplecticity_defect(mod, method, h=0.1, eps=1e-5):
    """max |Psi^T J Psi - J| with Psi the Jacobian of the step map by central differences."""
    p = params(mod)
    n = mod.N_COORDS
    q0, v0 = (np.array(x) for x in STATE)
    z0 = np.concatenate([q0, mass_matrix(mod, q0, p) @ v0])
    phi = momentum_map(mod, method, h, p)
    Psi = np.empty((2 * n, 2 * n))
    for j in range(2 * n):
        dz = np.zeros(2 * n)
        dz[j] = eps
        Psi[:, j] = (phi(z0 + dz) - phi(z0 - dz)) / (2 * eps)
    J = np.block([[np.zeros((n, n)), np.eye(n)], [-np.eye(n), np.zeros((n, n))]])
    return np.abs(Psi.T @ J @ Psi - J).max()


def test_the_specs_claim_the_known_properties():
    """The lists above derive from the specs: they hold at least the methods known to be
    symmetric (symplectic), so a spec losing its flag cannot drop a method from the checks."""
    assert {"verlet", "midpoint", "composition", "composition6"} <= set(SYMMETRIC)
    assert {"verlet", "midpoint", "composition", "composition6",
            "symplectic_euler"} <= set(SYMPLECTIC)


@pytest.mark.parametrize("method", SYMPLECTIC)
def test_symplectic_step_map(model, method):
    assert symplecticity_defect(model("double_pendulum"), method) < 1e-7


@pytest.mark.parametrize("method", ["explicit_euler", "rk4", "implicit_euler"])
def test_non_symplectic_methods_fail_the_check(model, method):
    assert symplecticity_defect(model("double_pendulum"), method) > 1e-5
