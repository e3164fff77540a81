"""Equilibria and linearizations of a generated model from its exact derivative kernels.

    q_eq = lg.equilibrium(module, q_guess, u=[0.0])
    A, B, C, D = lg.linearize(module, q_eq, [0, 0], u=[0.0])
    K = lqr(A, B)                                   # e.g. scipy.linalg.solve_continuous_are

State x = (q, qd) (2n,); dx/dt = A dx + B du, dy = C dx + D du. With H qdd = rhs(q, qd, t, p):
    d qdd/dq = H^-1 (d rhs/dq - d(H a)/dq |a),  d qdd/dqd = H^-1 d rhs/dqd,  d qdd/du = H^-1 d rhs/du
from the generated ``rhs_jacobian``, ``mass_matvec_dq`` and ``input_jacobian`` (a = qdd held
fixed in d(H a)/dq); C and D from ``output_jacobian``. Nothing is differenced numerically except
d gamma/dq of a constrained model off rest (gamma is quadratic in qd: zero at qd = 0).

Constrained models (H qdd = rhs + J^T lam, J qdd = gamma): the derivatives of the KKT solution
(qdd, lam), restricted to minimal coordinates z on the constraint manifold: q = q* + N z,
qd = N zd with N (n, n - m) an orthonormal basis of the null space of J(q*)
(``constraint_basis``); the state is then (z, zd) (2 (n - m),). At rest (qd = 0, the usual
case: an equilibrium) this is the linearization in any minimal coordinates with that tangent;
off rest it is the projection of the full-coordinate linearization onto the tangent space.

Models with nonholonomic constraints (velocity constraints, alone or beside holonomic ones) are
linearized in minimal coordinates and minimal speeds by linear/nonholonomic.py, about an
equilibrium or a steady motion; the shared argument handling is linear/arguments.py.
"""

from __future__ import annotations

import warnings
from typing import NamedTuple

import numpy as np

from ..errors import SimulationError
from ..run.control import input_slots
from .arguments import as_vector, need_kernels, parameter_vector
from .nonholonomic import linearize_nonholonomic

__all__ = ["Linearization", "equilibrium", "linearize", "constraint_basis", "parameter_vector"]


class Linearization(NamedTuple):
    """Continuous-time A (N, N), B (N, n_inputs), C (n_outputs, N), D (n_outputs, n_inputs);
    N = 2n, or 2 (n - m) in minimal coordinates for a constrained model."""

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray


def _refuse_nonholonomic(module, what):
    """An equilibrium of a model with velocity constraints (its multipliers and the holonomic
    ones together): not implemented, so refused rather than answered without them."""
    if getattr(module, "N_NONHOLONOMIC", 0):
        raise SimulationError(f"{module.NAME}: {what} of a model with nonholonomic constraints "
                              "is not implemented yet")


def accel_jacobians(module, q, qd, t, p):
    """(a (n,), lam (m,), da/dq, da/dqd (n, n), da/du (n, k)): the derivatives of the
    accelerations (for a constrained model of the KKT solution) at (q, qd, u in p)."""
    n, m = module.N_COORDS, module.N_CONSTRAINTS
    first, k = input_slots(module)
    H, rhs = np.zeros((n, n)), np.zeros(n)
    module.dynamics(q, qd, t, p, H, rhs)
    Jq, Jqd, Ju = np.zeros((n, n)), np.zeros((n, n)), np.zeros((n, k))
    module.rhs_jacobian(q, qd, t, p, Jq, Jqd)
    if k:
        module.input_jacobian(q, qd, t, p, Ju)
    if not m:
        a = np.linalg.solve(H, rhs)
        Da = np.zeros((n, n))
        module.mass_matvec_dq(q, a, t, p, Da)
        return a, np.zeros(0), np.linalg.solve(H, Jq - Da), np.linalg.solve(H, Jqd), np.linalg.solve(H, Ju)
    phi, J, gamma = np.zeros(m), np.zeros((m, n)), np.zeros(m)
    module.constraints(q, qd, t, p, phi, J, gamma)
    K = np.block([[H, -J.T], [J, np.zeros((m, m))]])
    sol = np.linalg.solve(K, np.concatenate((rhs, gamma)))
    a, lam = sol[:n], sol[n:]
    Da, dJa, dJTlam = np.zeros((n, n)), np.zeros((m, n)), np.zeros((n, n))
    module.mass_matvec_dq(q, a, t, p, Da)
    module.constraint_dq(q, a, lam, t, p, dJa, dJTlam)
    dgam_dq = _dgamma_dq(module, q, qd, t, p) if np.any(qd) else np.zeros((m, n))
    dJqd = np.zeros((m, n))
    module.constraint_dq(q, qd, lam, t, p, dJqd, np.zeros((n, n)))
    # gamma = -(d(J qd)/dq) qd, so d gamma/dqd = -2 d(J qd)/dq.
    rhs_q = np.vstack((Jq - Da + dJTlam, dgam_dq - dJa))
    rhs_qd = np.vstack((Jqd, -2.0 * dJqd))
    rhs_u = np.vstack((Ju, np.zeros((m, k))))
    d = [np.linalg.solve(K, r)[:n] for r in (rhs_q, rhs_qd, rhs_u)]
    return a, lam, d[0], d[1], d[2]


def _dgamma_dq(module, q, qd, t, p, eps=1e-6):
    """d gamma/dq (m, n) by central differences (third derivatives of Phi are not generated)."""
    n, m = module.N_COORDS, module.N_CONSTRAINTS
    out = np.zeros((m, n))
    for j in range(n):
        g = []
        for s in (1.0, -1.0):
            qs = q.copy()
            qs[j] += s * eps * max(1.0, abs(q[j]))
            phi, J, gamma = np.zeros(m), np.zeros((m, n)), np.zeros(m)
            module.constraints(qs, qd, t, p, phi, J, gamma)
            g.append(gamma)
        out[:, j] = (g[0] - g[1]) / (2 * eps * max(1.0, abs(q[j])))
    return out


def constraint_basis(module, q, params=None, t=0.0):
    """N (n, n - m): orthonormal basis of the null space of J(q, t) (from the SVD)."""
    n, m = module.N_COORDS, module.N_CONSTRAINTS
    if not m:
        return np.eye(n)
    p = parameter_vector(module, params)
    phi, J, gamma = np.zeros(m), np.zeros((m, n)), np.zeros(m)
    module.constraints(as_vector(q, n, "q", module), np.zeros(n), float(t), p, phi, J, gamma)
    return np.linalg.svd(J)[2][m:].T.copy()


def linearize(module, q, qd=None, u=None, t=0.0, params=None, coordinates=None,
              speeds=None) -> Linearization:
    """A, B, C, D of the model at (q, qd, u, t) (see the module docstring); ``module`` a
    generated module or a model file. C, D have 0 rows for a model without outputs; B, D have
    0 columns for a model without inputs (Model(inputs=)), with one warning line saying so.

    A model with nonholonomic constraints is linearized in minimal coordinates and minimal
    speeds (state (z, u), lagrange_gen.linear.nonholonomic; ``coordinates`` and ``speeds``
    name the independent ones, default chosen by pivoting); linearize_nonholonomic gives the
    second-order form M du' + C du + K dz as well."""
    from ..run.simulate import load_module
    module = load_module(module)
    if not getattr(module, "INPUTS", ()):
        warnings.warn(no_inputs_line(module), stacklevel=2)
    if getattr(module, "N_NONHOLONOMIC", 0):
        lin = linearize_nonholonomic(module, q, qd, u, t, params, coordinates, speeds)
        return Linearization(lin.A, lin.B, lin.C, lin.D)
    need_kernels(module, "rhs_jacobian", "mass_matvec_dq",
          *(("constraints", "constraint_dq") if module.N_CONSTRAINTS else ()))
    n = module.N_COORDS
    q, qd = as_vector(q, n, "q", module), as_vector(qd, n, "qd", module)
    p = parameter_vector(module, params, u)
    _, _, dq, dqd, du = accel_jacobians(module, q, qd, float(t), p)
    ny = getattr(module, "N_OUTPUTS", 0)
    Cq, Cqd, Du = np.zeros((ny, n)), np.zeros((ny, n)), np.zeros((ny, du.shape[1]))
    if ny:
        module.output_jacobian(q, qd, float(t), p, Cq, Cqd, Du)
    N = constraint_basis(module, q, params)
    r = N.shape[1]
    A = np.block([[np.zeros((r, r)), np.eye(r)], [N.T @ dq @ N, N.T @ dqd @ N]])
    B = np.vstack((np.zeros((r, du.shape[1])), N.T @ du))
    return Linearization(A, B, np.hstack((Cq @ N, Cqd @ N)), Du)


def no_inputs_line(module):
    """The one line linearize warns with on a model that declares no inputs (B (N, 0))."""
    x = module.COORDS[0] if module.COORDS else "x"
    frozen = ", ".join(getattr(module, "FROZEN", {}))
    return (f"{module.NAME} has no inputs, so B and D have 0 columns: declare one in the "
            f"model file, u = lg.inputs(\"u\", defaults=0.0) and Model(..., inputs=[u], "
            f"forces={{{x}: u}}) for a force on {x} (models/cart_pendulum_forced.py does)"
            + (f"; frozen in this module, so constants: {frozen}" if frozen else ""))


def equilibrium(module, q, u=None, t=0.0, params=None, tol=1e-12, max_iter=50):
    """q* (n,) with the generalized forces in balance at rest, rhs(q*, 0) (+ J^T lam) = 0 (and
    Phi(q*) = 0), by Newton from the guess q on the exact Jacobian d rhs/dq (with d(J^T lam)/dq
    and J for a constrained model). Steps are least-squares (minimum norm), so coordinates the
    forces do not fix (a free cart) stay at their guess. SimulationError when it does not
    converge."""
    from ..run.simulate import load_module
    module = load_module(module)
    _refuse_nonholonomic(module, "equilibrium")
    need_kernels(module, "rhs_jacobian", *(("constraints", "constraint_dq") if module.N_CONSTRAINTS else ()))
    n, m = module.N_COORDS, module.N_CONSTRAINTS
    x = np.concatenate((as_vector(q, n, "q", module), np.zeros(m)))
    p, zero = parameter_vector(module, params, u), np.zeros(n)
    for _ in range(max_iter):
        R, G = _balance(module, x[:n], x[n:], float(t), p, zero)
        dx = np.linalg.lstsq(G, -R, rcond=None)[0]
        x += dx
        if np.max(np.abs(dx)) <= tol * max(1.0, np.max(np.abs(x))) and np.max(np.abs(R)) < 1e-8:
            return x[:n]
    raise SimulationError(f"{module.NAME}: equilibrium: Newton did not converge in {max_iter} "
                          f"iterations from q = {np.asarray(q).tolist()} (residual "
                          f"{np.max(np.abs(R)):.3g}); try another guess")


def _balance(module, q, lam, t, p, zero):
    """Residual (rhs + J^T lam, Phi) (n + m,) at rest and its Jacobian w.r.t. (q, lam)."""
    n, m = module.N_COORDS, module.N_CONSTRAINTS
    H, rhs, Jq, Jqd = np.zeros((n, n)), np.zeros(n), np.zeros((n, n)), np.zeros((n, n))
    module.dynamics(q, zero, t, p, H, rhs)
    module.rhs_jacobian(q, zero, t, p, Jq, Jqd)
    if not m:
        return rhs, Jq
    phi, J, gamma = np.zeros(m), np.zeros((m, n)), np.zeros(m)
    module.constraints(q, zero, t, p, phi, J, gamma)
    dJw, dJTlam = np.zeros((m, n)), np.zeros((n, n))
    module.constraint_dq(q, zero, lam, t, p, dJw, dJTlam)
    G = np.block([[Jq + dJTlam, J.T], [J, np.zeros((m, m))]])
    return np.concatenate((rhs + J.T @ lam, phi)), G
