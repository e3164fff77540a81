"""Consistent initial conditions for models with holonomic constraints Phi(q, t) = 0.

A constrained method needs q0 on the manifold Phi(q0, t0) = 0 and v0 satisfying the velocity
constraint J(q0) v0 + dPhi/dt = 0 (tangent to the manifold when the constraints are
scleronomic; dPhi/dt from the generated ``constraint_rate``). Every function takes the time t
(default 0) at which the constraints are evaluated.
``consistent_initial_state`` projects a user's (q0, v0) there and warns by how much it moved them:

* positions: Gauss-Newton with the minimum-norm step in the metric of H(q) (the kinetic-energy
  metric, so a heavy coordinate moves less than a light one),
      dq = -H^-1 J^T (J H^-1 J^T)^-1 Phi(q),
  with step halving while max|Phi| does not decrease; it fails with a ConstraintError that names
  the constraints still violated when Phi cannot be brought to zero from q0 (no real solution
  nearby, or the iteration reaches a point where J loses rank);
* velocities: the closest tangent velocity in the same metric (least squares),
      v = v0 - H^-1 J^T (J H^-1 J^T)^-1 (J v0 + dPhi/dt);
  with ``keep`` (velocity names), the kept velocities stay and only the others (F) change, by
  the same formula on the free block: dv_F = -H_FF^-1 J_F^T (J_F H_FF^-1 J_F^T)^+ (J v0 +
  dPhi/dt); a ConstraintError when J v + dPhi/dt = 0 cannot be met that way (J_F lacks rank
  for the kept values);
* multipliers lam0 from the acceleration-level KKT system at (q, v), the constraint forces of
  the initial state (row 0 of Trajectory.multipliers).

For nonholonomic constraints A(q, t) v + b = 0 ``nonholonomic_start`` projects v0 by the same
velocity formula with A, b in place of J, dPhi/dt (stacked under J, dPhi/dt when the model has
holonomic constraints too, after q0 is projected onto Phi = 0).

Redundant constraints (rank-deficient J at q0) are refused, not handled by a least-squares
multiplier: their multipliers are not unique, and the methods' Newton matrices are singular.
The error names the constraints that are dependent (a left null vector of J).

All arrays are numpy: q, v (n,), Phi, lam (m,), J (m, n), H (n, n); p the parameter vector.

Over 300 lines: the projections of positions and velocities, the multipliers, the rank and
singularity diagnoses and the nonholonomic start share the constraint evaluations above.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from ..errors import SimulationError

#: Relative singular value of the row-normalized J below which constraints count as dependent.
RANK_RTOL = 1e-9


class ConstraintError(SimulationError):
    """The constraints are redundant, or cannot be satisfied from the given initial state."""


@dataclass
class ConsistentState:
    """Projected initial state: q, v (n,), lam (m,), the residuals max|Phi(q)|, max|J v| after
    projection, and how far the projection moved q0 and v0 (max norms)."""

    q: np.ndarray
    v: np.ndarray
    lam: np.ndarray
    phi_norm: float
    jv_norm: float
    dq: float
    dv: float


def evaluate(module, q, v, p, t=0.0):
    """Phi (m,), J (m, n), gamma (m,) at (q, v, t) from the generated ``constraints`` kernel."""
    n, m = module.N_COORDS, module.N_CONSTRAINTS
    phi, J, gamma = np.empty(m), np.empty((m, n)), np.empty(m)
    module.constraints(np.ascontiguousarray(q, dtype=float), np.ascontiguousarray(v, dtype=float),
                       float(t), p, phi, J, gamma)
    return phi, J, gamma


def rate(module, q, p, t=0.0):
    """dPhi/dt (m,) at (q, t) (zeros for scleronomic constraints)."""
    out = np.zeros(module.N_CONSTRAINTS)
    if getattr(module, "CONSTRAINTS_RHEONOMIC", False):
        module.constraint_rate(np.ascontiguousarray(q, dtype=float), float(t), p, out)
    return out


def mass(module, q, p, t=0.0):
    n = module.N_COORDS
    H = np.empty((n, n))
    module.mass_matrix(np.ascontiguousarray(q, dtype=float), float(t), p, H)
    return H


def constraint_label(module, i):
    return f"constraint {i} ({module.CONSTRAINTS[i]} = 0)"


def dependent_constraints(J):
    """Indices of constraints whose gradients are linearly dependent (rows of J, each scaled to
    unit length), or () when J has full row rank."""
    norms = np.linalg.norm(J, axis=1)
    zero = np.flatnonzero(norms == 0.0)
    if zero.size:
        return tuple(int(i) for i in zero)
    U, s, _ = np.linalg.svd(J / norms[:, None])
    if s.size == J.shape[0] and s[-1] > RANK_RTOL * s[0]:
        return ()
    null = U[:, -1]
    return tuple(int(i) for i in np.flatnonzero(np.abs(null) > 1e-6 * np.abs(null).max()))


def check_rank(module, q, p, where="at q0", t=0.0):
    """Raise ConstraintError naming the dependent constraints when J(q) is rank-deficient."""
    _, J, _ = evaluate(module, q, np.zeros_like(q), p, t)
    bad = dependent_constraints(J)
    if bad:
        names = "; ".join(constraint_label(module, i) for i in bad)
        rank = np.linalg.matrix_rank(J / np.maximum(np.linalg.norm(J, axis=1), 1e-300)[:, None],
                                     tol=RANK_RTOL)
        raise ConstraintError(
            f"{module.NAME}: redundant or degenerate constraints {where} (rank of J = {rank} < "
            f"{module.N_CONSTRAINTS}): {names}; their gradients are linearly dependent, so the "
            f"multipliers are not unique: remove the redundant one(s) or move q0 off the "
            f"singular configuration")


def scaled_violation(phi, J, q):
    """max_i |Phi_i| / max_j |J_ij| relative to max(1, max|q|): the distance to the manifold
    in the units of the Newton tolerance (relative to max(1, |q|), like the steppers')."""
    g = np.abs(J).max(axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        d = np.where(g > 0, np.abs(phi) / np.where(g > 0, g, 1.0), np.where(phi == 0, 0.0, np.inf))
    return float(d.max(initial=0.0)) / max(1.0, float(np.abs(q).max(initial=0.0)))


def _min_norm_step(H, J, r):
    """x = H^-1 J^T (J H^-1 J^T)^-1 r: the H-metric minimum-norm solution of J x = r."""
    Y = np.linalg.solve(H, J.T)
    return Y @ np.linalg.solve(J @ Y, r)


def project_positions(module, q0, p, tol=1e-12, max_iter=50, t=0.0):
    """q on Phi(q, t) = 0 near q0 (see the module docstring). Raises ConstraintError."""
    q = np.array(q0, dtype=float)
    phi, J, _ = evaluate(module, q, np.zeros_like(q), p, t)
    norm = np.abs(phi).max(initial=0.0)
    for _ in range(max_iter):
        if scaled_violation(phi, J, q) <= 1e-3 * tol:
            return q
        if dependent_constraints(J):
            break
        try:
            dq = -_min_norm_step(mass(module, q, p, t), J, phi)
        except np.linalg.LinAlgError:
            break
        step = 1.0
        while step > 1e-8:
            trial = q + step * dq
            phi_t, J_t, _ = evaluate(module, trial, np.zeros_like(q), p, t)
            if np.abs(phi_t).max() < norm or scaled_violation(phi_t, J_t, trial) <= tol:
                break
            step *= 0.5
        else:
            break
        q, phi, J, norm = trial, phi_t, J_t, np.abs(phi_t).max()
    if scaled_violation(phi, J, q) <= tol:
        return q
    worst = int(np.argmax(np.abs(phi)))
    raise ConstraintError(
        f"{module.NAME}: the constraints cannot be satisfied from q0 = {np.asarray(q0).tolist()}: "
        f"the Gauss-Newton projection stalled at q = {q.tolist()} with max|Phi| = {norm:.3g} "
        f"({constraint_label(module, worst)} has residual {phi[worst]:.3g}); check the constraint "
        f"equations and parameters, or give a q0 closer to Phi(q) = 0")


def project_velocities(module, q, v0, p, keep=(), t=0.0):
    """The velocity closest to v0 in the metric of H(q) with J(q) v + dPhi/dt = 0, changing only
    the velocities not named in ``keep`` (see the module docstring)."""
    _, J, _ = evaluate(module, q, v0, p, t)
    v = np.array(v0, dtype=float)
    H, phi_t = mass(module, q, p, t), rate(module, q, p, t)
    if not keep:
        return v - _min_norm_step(H, J, J @ v + phi_t)
    kept = kept_indices(module, keep)
    free = np.array([i for i in range(len(v)) if i not in kept], dtype=int)
    r = J @ v + phi_t
    if free.size:
        Y = np.linalg.solve(H[np.ix_(free, free)], J[:, free].T)
        v[free] -= Y @ np.linalg.lstsq(J[:, free] @ Y, r, rcond=None)[0]
    residual = np.abs(J @ v + phi_t).max(initial=0.0)
    if residual > 1e-9 * max(1.0, float(np.abs(v0).max(initial=0.0))) * max(1.0, float(np.abs(J).max())):
        names = [f"{module.COORDS[i]}_dot" for i in sorted(kept)]
        raise ConstraintError(
            f"{module.NAME}: keeping {', '.join(names)} at v0 leaves J v = 0 unsolvable (max|J v| "
            f"= {residual:.3g} at best with the other velocities free): keep fewer velocities, or "
            f"give kept values that satisfy the constraints")
    return v


def kept_indices(module, keep):
    """Indices of the velocities named in ``keep`` (theta_dot, or the coordinate theta);
    SimulationError naming an unknown one."""
    names = [f"{c}_dot" for c in module.COORDS]
    out = set()
    for name in keep:
        key = name if name in names else f"{name}_dot"
        if key not in names:
            raise SimulationError(f"{module.NAME}: keep {name!r} is not a velocity (velocities: "
                                  f"{', '.join(names)})")
        out.add(names.index(key))
    return out


def initial_multipliers(module, q, v, t, p):
    """lam (m,) from [[H, -J^T], [J, 0]] (qdd, lam) = (rhs, gamma) at (q, v, t)."""
    n, m = module.N_COORDS, module.N_CONSTRAINTS
    H, rhs = np.empty((n, n)), np.empty(n)
    module.dynamics(q, v, float(t), p, H, rhs)
    _, J, gamma = evaluate(module, q, v, p, t)
    K = np.block([[H, -J.T], [J, np.zeros((m, m))]])
    return np.linalg.solve(K, np.concatenate((rhs, gamma)))[n:]


def consistent_initial_state(module, q0, v0, p, t0=0.0, tol=1e-12, warn=True, stacklevel=2,
                             keep=None):
    """Project (q0, v0) onto the constraint manifold and its tangent space; ConsistentState.

    Warns (UserWarning) with the size of the violation and of the correction when q0 or v0 was
    off by more than the tolerance (in the scaled measure of ``scaled_violation``). Raises
    ConstraintError for redundant constraints or constraints that cannot be satisfied.
    stacklevel: of the warnings, as for warnings.warn (2: the caller of this function).
    keep: velocity names whose v0 the velocity projection keeps (project_velocities)."""
    q0, v0 = np.asarray(q0, dtype=float), np.asarray(v0, dtype=float)
    check_rank(module, q0, p, t=t0)
    phi0, J0, _ = evaluate(module, q0, v0, p, t0)
    q = project_positions(module, q0, p, tol, t=t0) if scaled_violation(phi0, J0, q0) > 1e-3 * tol else q0
    check_rank(module, q, p, where=f"at the projected q0 = {q.tolist()}", t=t0)
    _, J, _ = evaluate(module, q, v0, p, t0)
    jv0 = J @ v0 + rate(module, q, p, t0)
    v = project_velocities(module, q, v0, p, tuple(keep or ()), t0)
    dq, dv = float(np.abs(q - q0).max()), float(np.abs(v - v0).max())
    if warn and scaled_violation(phi0, J0, q0) > tol:
        worst = int(np.argmax(np.abs(phi0)))
        warnings.warn(f"{module.NAME}: q0 violates the constraints by max|Phi| = "
                      f"{np.abs(phi0).max():.3g} ({constraint_label(module, worst)}); projected "
                      f"onto Phi(q) = 0, moving q0 by max|dq| = {dq:.3g}", stacklevel=stacklevel)
    vscale = max(1.0, float(np.abs(v0).max()))
    gscale = np.maximum(np.abs(J).max(axis=1), 1e-300)
    if warn and float((np.abs(jv0) / gscale).max()) > tol * vscale:
        warnings.warn(f"{module.NAME}: v0 is not tangent to the constraints (max|J v0| = "
                      f"{np.abs(jv0).max():.3g}); replaced by the closest tangent velocity in the "
                      f"kinetic-energy metric{_kept_phrase(module, keep)}, changing v0 by "
                      f"max|dv| = {dv:.3g}",
                      stacklevel=stacklevel)
    phi, J, _ = evaluate(module, q, v, p, t0)
    lam = initial_multipliers(module, q, v, t0, p)
    return ConsistentState(q=q, v=v, lam=lam, phi_norm=float(np.abs(phi).max()),
                           jv_norm=float(np.abs(J @ v + rate(module, q, p, t0)).max()), dq=dq, dv=dv)


def _kept_phrase(module, keep):
    if not keep:
        return " (keep= / --keep names velocities to leave unchanged)"
    names = [f"{module.COORDS[i]}_dot" for i in sorted(kept_indices(module, keep))]
    return f" keeping {', '.join(names)}"


def check_method(module, method):
    """Refuse an unconstrained method on a constrained model and the other way round."""
    from ..steppers.core import registry
    m = getattr(module, "N_CONSTRAINTS", 0)
    why = registry.inapplicable(method, m, getattr(module, "N_ELEMENTS", 0),
                                getattr(module, "N_CONTACTS", 0),
                                getattr(module, "N_NONHOLONOMIC", 0))
    if not why:
        return
    # the list of constrained methods is the advice only where they apply (velocity
    # constraints beside holonomic ones need a nonholonomic method: ``why`` names it)
    if (m and not getattr(module, "N_NONHOLONOMIC", 0) and not registry.spec(method).constraints
            and not registry.spec(method).contacts):
        names = "; ".join(constraint_label(module, i) for i in range(m))
        about = "; ".join(f"{s.name}: order {s.order}, {s.summary}"
                          for s in map(registry.spec, registry.CONSTRAINED_METHODS))
        raise SimulationError(f"{module.NAME}: method {method!r} ignores the model's constraints "
                              f"({names}); use a constrained method: "
                              f"{', '.join(registry.CONSTRAINED_METHODS)} ({about})")
    if why.startswith("it "):
        raise SimulationError(f"{module.NAME}: method {method!r} {why[3:]}")
    raise SimulationError(f"{module.NAME}: method {method!r} does not apply: {why}")


def diagnose_singular(module, q, p):
    """A sentence naming the dependent constraints at q when J(q) is rank-deficient, else ''."""
    _, J, _ = evaluate(module, q, np.zeros_like(q), p)
    bad = dependent_constraints(J)
    if not bad:
        return ""
    return ("; the constraint gradients are linearly dependent there (redundant constraints or "
            "a singular configuration): " + "; ".join(constraint_label(module, i) for i in bad))


def nonholonomic_start(module, q, v0, p, t0=0.0, tol=1e-12, stacklevel=2):
    """(q, v): q0 on the holonomic constraints Phi(q, t0) = 0 if the model has any
    (project_positions, with a warning when it moved), and v0 projected onto the velocity
    constraints A(q, t0) v + b(q, t0) = 0 (generated ``nonholonomic`` kernel; with holonomic
    constraints also J v + dPhi/dt = 0, the rows stacked) in the kinetic-energy metric,
    v = v0 - H^-1 A^T (A H^-1 A^T)^-1 (A v0 + b): the velocity the constraints leave after an
    impulse that imposes them. Warns with the violation and the change when v0 was off by more
    than tol (relative to max(1, |v0|) and the rows' scale). q, v0 (n,)."""
    n, r = module.N_COORDS, module.N_NONHOLONOMIC
    q, v0 = np.asarray(q, dtype=float), np.asarray(v0, dtype=float)
    A, b, gamma = np.empty((r, n)), np.empty(r), np.empty(r)
    if module.N_CONSTRAINTS:
        moved = project_positions(module, q, p, tol, t=t0)
        if np.abs(moved - q).max() > tol * max(1.0, float(np.abs(q).max())):
            warnings.warn(f"{module.NAME}: q0 violates the holonomic constraints; replaced by "
                          f"the nearest q on them (max|dq| = {np.abs(moved - q).max():.3g})",
                          stacklevel=stacklevel)
        q = moved
    module.nonholonomic(q, v0, float(t0), p, A, b, gamma)
    if module.N_CONSTRAINTS:
        _, J, _ = evaluate(module, q, v0, p, t0)
        A, b = np.vstack((J, A)), np.concatenate((rate(module, q, p, t0), b))
        r = A.shape[0]
    residual = A @ v0 + b
    scale = np.maximum(np.abs(A).max(axis=1), 1e-300) * max(1.0, float(np.abs(v0).max()))
    if float((np.abs(residual) / scale).max(initial=0.0)) <= tol:
        return q, v0
    if np.linalg.matrix_rank(A) < r:
        raise ConstraintError(f"{module.NAME}: the nonholonomic constraints are dependent at "
                              f"q0 = {q.tolist()} (A has rank {np.linalg.matrix_rank(A)} < {r})")
    v = v0 - _min_norm_step(mass(module, q, p, t0), A, residual)
    warnings.warn(f"{module.NAME}: v0 violates the nonholonomic constraints (max|A v0 + b| = "
                  f"{np.abs(residual).max():.3g}); replaced by the closest velocity that meets "
                  f"them in the kinetic-energy metric, changing v0 by max|dv| = "
                  f"{np.abs(v - v0).max():.3g}", stacklevel=stacklevel)
    return q, v
