"""Linearization of a model with nonholonomic constraints about an equilibrium or a steady
motion, in minimal coordinates and minimal (independent) speeds.

    lin = lg.linearize_nonholonomic("models/bicycle.py", q, qd,
                                    speeds=("phi", "delta", "theta_R"))
    lin.mass, lin.damping, lin.stiffness   # M du' + C du + K dz = F dinput
    lin.A                                  # d(dz, du)/dt = A (dz, du) + B dinput

The motion: H qdd = rhs(q, qd, t) + J^T lam + A^T mu with the holonomic constraints Phi(q) = 0
(m, J = dPhi/dq, J qdd = gamma_J) and the velocity constraints A(q) qd + b(q) = 0 (r,
A qdd = gamma_A): the velocities live in the null space of the stacked rows C = [J; A]
(m + r, n). Coordinates: n - m of the q are independent (z, ``coordinates``), the others follow
from Phi = 0; speeds: k = n - m - r of the qd are independent (u, ``speeds``), the others
follow from C qd + (0; b) = 0 (Kane's dependent speeds). About a reference (q*, qd*) whose
accelerations vanish (rest, or a steady motion in cyclic coordinates, such as a bicycle
running straight upright):

  - the accelerations' derivatives d a/dq, d a/dqd come from the KKT system
    [[H, -C^T], [C, 0]] (a, lam, mu) = (rhs, gamma_J, gamma_A) differentiated exactly with the
    generated kernels (rhs_jacobian, mass_matvec_dq, constraint_dq, constraint_gamma_dq,
    nonholonomic_dq: nothing is differenced numerically);
  - a perturbation (dz, du) of the reduced state is the tangent (dq, dqd) of the constraint
    manifold: dq = N dz with J N = 0 and N = I on the independent coordinates; dqd = S du + W dz
    with C S = 0, S = I on the independent speeds (S's columns are the partial velocities),
    C W = -d(C qd + (0; b))/dq N and W = 0 on the independent speeds;
  - dz' = (S du + W dz) on the independent coordinates, du' = (da/dq N dz + da/dqd (S du + W dz))
    on the independent speeds.

The second-order form: the reduced equations S^T (H qdd - rhs) = 0 (the constraint forces drop
out: C S = 0) have the leading matrix M = S^T H S, so M du' + C_u du + K dz = F dinput with
C_u = -M du'/du, K = -M du'/dz, F = M du'/dinput. For the Whipple bicycle with speeds (lean
rate, steer rate, rear wheel rate) the lean and steer rows and columns are the benchmark's M,
v C1 and g K0 + v^2 K2 (Meijaard et al., Proc. R. Soc. A 463, 2007).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..errors import SimulationError
from ..run.control import input_slots
from .arguments import as_vector, need_kernels, parameter_vector

__all__ = ["ReducedLinearization", "linearize_nonholonomic"]


class ReducedLinearization(NamedTuple):
    """The linearization in minimal coordinates z (nz = n - m) and minimal speeds u (k).

    A (nz + k, nz + k), B (nz + k, n_inputs): d(dz, du)/dt = A (dz, du) + B dinput;
    C (n_outputs, nz + k), D (n_outputs, n_inputs): dy = C (dz, du) + D dinput.
    mass (k, k) = S^T H S, damping (k, k), stiffness (k, nz), forcing (k, n_inputs):
    mass du' + damping du + stiffness dz = forcing dinput. kinematics (nz, nz + k): dz' =
    kinematics (dz, du). partial_velocities S (n, k) and coordinate_basis N (n, nz): dq = N dz,
    dqd = S du + W dz. coordinates, speeds: the names of z and of u (velocities' names)."""

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    mass: np.ndarray
    damping: np.ndarray
    stiffness: np.ndarray
    forcing: np.ndarray
    kinematics: np.ndarray
    partial_velocities: np.ndarray
    coordinate_basis: np.ndarray
    coordinates: tuple
    speeds: tuple


def linearize_nonholonomic(module, q, qd=None, u=None, t=0.0, params=None, coordinates=None,
                           speeds=None) -> ReducedLinearization:
    """The reduced linearization of a model with nonholonomic constraints at (q, qd, u, t) (see
    the module docstring). ``module``: a generated module or a model file; q, qd (n,) satisfy
    the constraints; coordinates: names (or indices) of the n - m independent coordinates,
    speeds: of the n - m - r independent speeds (default: chosen by pivoting on J and on
    [J; A], preferring the model's order). SimulationError (one line) for a wrong count or a
    choice that leaves the dependent block singular. About a steady motion choose speeds that
    stay constant along it (a wheel's rate, not a velocity component that turns with the
    heading): the linearization is then time-invariant and its eigenvalues mean stability."""
    from ..run.simulate import load_module
    module = load_module(module)
    n, m, r = module.N_COORDS, module.N_CONSTRAINTS, getattr(module, "N_NONHOLONOMIC", 0)
    if getattr(module, "CONSTRAINTS_RHEONOMIC", False):
        raise SimulationError(f"{module.NAME}: linearize with nonholonomic constraints needs "
                              "holonomic constraints that do not depend on t")
    need_kernels(module, "rhs_jacobian", "mass_matvec_dq", *(("nonholonomic", "nonholonomic_dq") if r else ()),
          *(("constraints", "constraint_dq", "constraint_gamma_dq") if m else ()))
    q, qd = as_vector(q, n, "q", module), as_vector(qd, n, "qd", module)
    t = float(t)
    p = parameter_vector(module, params, u)
    rows = _constraint_rows(module, q, qd, t, p)
    C, violation = rows["C"], np.max(np.abs(rows["residual"]), initial=0.0)
    if violation > 1e-8 * max(1.0, np.max(np.abs(qd), initial=0.0)):
        raise SimulationError(f"{module.NAME}: linearize: (q, qd) violates the constraints "
                              f"(max residual {violation:.3g}); give a state on them")
    z_idx = _independent(module, rows["J"], coordinates, n - m, "coordinates", module.COORDS)
    u_idx = _independent(module, C, speeds, n - m - r, "speeds", module.VELOCITIES)
    da_dq, da_dqd, da_du = _acceleration_jacobians(module, q, qd, t, p, rows)
    N = _basis(module, rows["J"], z_idx, "coordinates")
    S = _basis(module, C, u_idx, "speeds")
    W = _velocity_shift(C, rows["dC"] @ N, u_idx)
    nz = N.shape[1]
    kin = np.hstack((W[z_idx], S[z_idx]))
    acc = np.hstack((da_dq @ N + da_dqd @ W, da_dqd @ S))[u_idx]
    A = np.vstack((kin, acc))
    B = np.vstack((np.zeros((nz, da_du.shape[1])), da_du[u_idx]))
    H = np.zeros((n, n))
    module.mass_matrix(q, t, p, H)
    M = S.T @ H @ S
    Cy, Dy = _outputs(module, q, qd, t, p, N, S, W, da_du.shape[1])
    return ReducedLinearization(
        A, B, Cy, Dy, M, -M @ acc[:, nz:], -M @ acc[:, :nz], M @ B[nz:], kin, S, N,
        tuple(module.COORDS[i] for i in z_idx), tuple(module.VELOCITIES[i] for i in u_idx))


def _constraint_rows(module, q, qd, t, p):
    """The stacked constraint rows at (q, qd): J (m, n), C = [J; A] (m + r, n), gamma (m + r,),
    the velocity residual C qd + (0; b) (m + r,) and d(C qd + (0; b))/dq (m + r, n); the
    holonomic residual Phi is appended to the residual."""
    n, m, r = module.N_COORDS, module.N_CONSTRAINTS, getattr(module, "N_NONHOLONOMIC", 0)
    J, phi, gam_J = np.zeros((m, n)), np.zeros(m), np.zeros(m)
    A, b, gam_A = np.zeros((r, n)), np.zeros(r), np.zeros(r)
    dJqd, dc = np.zeros((m, n)), np.zeros((r, n))
    if m:
        module.constraints(q, qd, t, p, phi, J, gam_J)
        module.constraint_dq(q, qd, np.zeros(m), t, p, dJqd, np.zeros((n, n)))
    if r:
        module.nonholonomic(q, qd, t, p, A, b, gam_A)
        module.nonholonomic_dq(q, qd, qd, np.zeros(r), t, p, np.zeros((r, n)), np.zeros((n, n)),
                               dc, np.zeros((r, n)), np.zeros((r, n)))
    C = np.vstack((J, A))
    residual = np.concatenate((phi, J @ qd, A @ qd + b))
    return dict(J=J, C=C, gamma=np.concatenate((gam_J, gam_A)), residual=residual,
                dC=np.vstack((dJqd, dc)))


def _acceleration_jacobians(module, q, qd, t, p, rows):
    """d a/dq, d a/dqd (n, n) and d a/dinput (n, n_inputs) of the KKT accelerations."""
    n, m, r = module.N_COORDS, module.N_CONSTRAINTS, getattr(module, "N_NONHOLONOMIC", 0)
    first, k_in = input_slots(module)
    H, rhs = np.zeros((n, n)), np.zeros(n)
    module.dynamics(q, qd, t, p, H, rhs)
    Jq, Jqd, Ju = np.zeros((n, n)), np.zeros((n, n)), np.zeros((n, k_in))
    module.rhs_jacobian(q, qd, t, p, Jq, Jqd)
    if k_in:
        module.input_jacobian(q, qd, t, p, Ju)
    C, s = rows["C"], m + r
    K = np.block([[H, -C.T], [C, np.zeros((s, s))]])
    sol = np.linalg.solve(K, np.concatenate((rhs, rows["gamma"])))
    a, lam, mu = sol[:n], sol[n:n + m], sol[n + m:]
    Da = np.zeros((n, n))
    module.mass_matvec_dq(q, a, t, p, Da)
    force_q = Jq - Da                         # d(rhs - H a + C^T (lam, mu))/dq at fixed a, lam, mu
    row_q, row_qd = np.zeros((s, n)), np.zeros((s, n))   # d(gamma - C a)/dq, d gamma/dqd
    if m:
        dJa, dJTlam, dg_q, dg_qd = np.zeros((m, n)), np.zeros((n, n)), np.zeros((m, n)), np.zeros((m, n))
        module.constraint_dq(q, a, lam, t, p, dJa, dJTlam)
        module.constraint_gamma_dq(q, qd, t, p, dg_q, dg_qd)
        force_q += dJTlam
        row_q[:m], row_qd[:m] = dg_q - dJa, dg_qd
    if r:
        dAa, dATmu, dc = np.zeros((r, n)), np.zeros((n, n)), np.zeros((r, n))
        dg_q, dg_qd = np.zeros((r, n)), np.zeros((r, n))
        module.nonholonomic_dq(q, qd, a, mu, t, p, dAa, dATmu, dc, dg_q, dg_qd)
        force_q += dATmu
        row_q[m:], row_qd[m:] = dg_q - dAa, dg_qd
    rhs_all = np.hstack((np.vstack((force_q, row_q)), np.vstack((Jqd, row_qd)),
                         np.vstack((Ju, np.zeros((s, k_in))))))
    d = np.linalg.solve(K, rhs_all)[:n]
    return d[:, :n], d[:, n:2 * n], d[:, 2 * n:]


def _independent(module, rows, chosen, count, what, names):
    """Indices (sorted) of the independent coordinates or speeds: the ``chosen`` names or
    indices, else the columns left after picking the dependent ones by complete pivoting on
    ``rows`` (s, n)."""
    n = rows.shape[1]
    if chosen is not None:
        idx = []
        for c in chosen:
            if not isinstance(c, str):
                idx.append(int(c))
            elif c in module.COORDS or c in names:
                idx.append(list(module.COORDS if c in module.COORDS else names).index(c))
            else:
                raise SimulationError(f"{module.NAME}: linearize: {what}: unknown name {c!r} "
                                      f"(known: {', '.join(module.COORDS)})")
        if len(set(idx)) != count:
            raise SimulationError(f"{module.NAME}: linearize: {what} names {len(set(idx))} "
                                  f"distinct entries; the model has {count} independent {what}")
        return sorted(idx)
    work, dependent = rows.copy(), []
    for _ in range(rows.shape[0]):
        scores = np.max(np.abs(work), axis=0) if work.size else np.zeros(n)
        scores[dependent] = -1.0
        # the largest entry (a stable elimination); ties within round-off go to the earlier
        # column (a contact point's coordinates, listed first, become the dependent ones)
        best = min(j for j in range(n) if scores[j] >= (1.0 - 1e-9) * scores.max())
        row = int(np.argmax(np.abs(work[:, best])))
        pivot = work[row] / work[row, best]
        work = np.delete(work - np.outer(work[:, best], pivot), row, axis=0)
        dependent.append(best)
    return [j for j in range(n) if j not in dependent]


def _basis(module, rows, independent, what):
    """B (n, len(independent)) with rows @ B = 0 and B = I on the independent columns."""
    n = rows.shape[1]
    dep = [j for j in range(n) if j not in independent]
    B = np.zeros((n, len(independent)))
    B[independent] = np.eye(len(independent))
    if dep:
        block = rows[:, dep]
        if np.linalg.matrix_rank(block) < len(dep):
            raise SimulationError(f"{module.NAME}: linearize: the dependent {what} "
                                  f"({', '.join(module.COORDS[j] for j in dep)}) are not "
                                  "fixed by the constraints here; choose other independent "
                                  f"{what}")
        B[dep] = -np.linalg.solve(block, rows[:, independent])
    return B


def _velocity_shift(C, dC_N, independent):
    """W (n, nz): the dependent speeds' change with the coordinates, C W = -dC_N, W = 0 on the
    independent speeds."""
    n = C.shape[1]
    dep = [j for j in range(n) if j not in independent]
    W = np.zeros((n, dC_N.shape[1]))
    if dep:
        W[dep] = -np.linalg.solve(C[:, dep], dC_N)
    return W


def _outputs(module, q, qd, t, p, N, S, W, k_in):
    """C (n_outputs, nz + k), D (n_outputs, n_inputs) of the model's outputs."""
    ny, n = getattr(module, "N_OUTPUTS", 0), module.N_COORDS
    Cq, Cqd, Du = np.zeros((ny, n)), np.zeros((ny, n)), np.zeros((ny, k_in))
    if ny:
        module.output_jacobian(q, qd, t, p, Cq, Cqd, Du)
    return np.hstack((Cq @ N + Cqd @ W, Cqd @ S)), Du
