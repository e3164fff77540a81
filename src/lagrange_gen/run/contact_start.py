"""An initial state inside a unilateral contact (a gap g_i(q0, t0) < 0): said, then refused or
projected out.

No contact method is meant to start inside a contact: spook_contacts' stabilization pushes the
body out with the full depth in a step or two (a ball released 0.5 m inside the floor leaves
at hundreds of m/s), moreau_jean and dop853_impacts hold it inside (their impacts act on
velocities only). So simulate checks the gaps of q0 before a contact method runs and, by
``penetration`` (simulate's option):

* "project" (the default): one warning line naming the deepest contact and its gap, then
      q  = the point of g(q, t0) >= 0 nearest q0 in the metric of H(q) (with Phi(q, t0) = 0 as
           well on a model with holonomic constraints): Gauss-Newton on the linearized set,
           min (dq^T H dq) / 2 subject to g + W_N dq >= 0, J dq = -Phi, each step a small
           active-set solve (``metric_projection``);
      v  = the velocity nearest v0 in the same metric whose normal velocities at the contacts
           now closed (g <= tolerance) do not approach, W_N v + dg/dt >= 0: an inelastic
           impulse v = v0 + H^-1 W_N^T lam, lam >= 0 (kinetic energy never rises: the nearest
           point of a convex set that holds 0 when the surfaces are fixed).
  The velocity change adds no kinetic energy and nothing launches the body; moving q0 changes
  the potential energy by what the warning reports (that is the user's q0 moved, not energy
  that appears during the run).
* "refuse": ContactPenetration, one line naming the contact and its gap;
* "keep": the warning only, (q0, v0) unchanged (to watch a method's own handling of a
  penetration, e.g. spook_contacts' stabilization, which may launch the body).

Arrays: q, v (n,), g (c,), W_N (c, n), H (n, n), J (m, n), Phi (m,).
"""

from __future__ import annotations

import warnings

import numpy as np

from ..errors import SimulationError

#: simulate(penetration=...): what a q0 inside a contact does.
PENETRATION_MODES = ("project", "refuse", "keep")

#: A gap below -GAP_TOL max(1, |q0|) counts as a start inside the contact (rounding above it).
GAP_TOL = 1e-9


class ContactPenetration(SimulationError):
    """q0 lies inside a unilateral contact and penetration="refuse"."""


def contact_gaps(module, q, p, t=0.0):
    """g (c,), W_N (c, n) at (q, t) from the generated ``contacts`` kernel."""
    c, n = module.N_CONTACTS, module.N_COORDS
    g, WN, WT, coef = np.empty(c), np.empty((c, n)), np.empty((2 * c, n)), np.empty((c, 2))
    module.contacts(np.ascontiguousarray(q, dtype=float), float(t), p, g, WN, WT, coef)
    return g, WN


def normal_bias(module, q, p, t=0.0):
    """dg/dt (c,) at (q, t): the normal velocities are W_N v + these (a moving surface)."""
    out = np.zeros(3 * module.N_CONTACTS)
    if hasattr(module, "contact_bias"):
        module.contact_bias(np.ascontiguousarray(q, dtype=float), float(t), p, out)
    return out[:module.N_CONTACTS]


def metric_projection(H, W, r, E=None, s=None, max_rounds=None):
    """x minimizing x^T H x / 2 subject to W x + r >= 0 (W (k, n), r (k,)) and E x + s = 0
    (E (m, n), s (m,); none by default): an active-set method from no active row (each round
    solves the KKT system of the rows held as equalities; a row whose multiplier turns negative
    leaves, else the most violated row outside joins, so a row that duplicates a held one is
    not added while it is met). Returns (x (n,), lam (k,) >= 0, the multipliers of W).
    H symmetric positive definite; small k (contacts) in mind."""
    n, k = H.shape[0], W.shape[0]
    E = np.zeros((0, n)) if E is None else E
    s = np.zeros(0) if s is None else s
    active = []
    x, lam = np.zeros(n), np.zeros(k)
    scale = max(1.0, float(np.abs(r).max(initial=0.0)))
    for _ in range(max_rounds or 4 * k + 10):
        rows = np.vstack((W[active], E)) if active else E
        rhs = -np.concatenate((r[active], s)) if active else -s
        if rows.shape[0]:
            Y = np.linalg.solve(H, rows.T)
            mult = np.linalg.lstsq(rows @ Y, rhs, rcond=None)[0]
            x = Y @ mult
        else:
            mult, x = np.zeros(0), np.zeros(n)
        lam = np.zeros(k)
        lam[active] = mult[:len(active)]
        if active and lam[active].min() < 0.0:
            active.remove(active[int(np.argmin(lam[active]))])
            continue
        slack = W @ x + r
        outside = [i for i in range(k) if i not in active]
        if outside and slack[outside].min() < -1e-12 * scale:
            active.append(outside[int(np.argmin(slack[outside]))])
            continue
        break
    return x, np.maximum(lam, 0.0)


def _holonomic(module, q, p, t):
    """(Phi (m,), J (m, n)): the holonomic constraints (empty without)."""
    if not getattr(module, "N_CONSTRAINTS", 0):
        n = module.N_COORDS
        return np.zeros(0), np.zeros((0, n))
    from .consistent import evaluate
    phi, J, _ = evaluate(module, q, np.zeros_like(q), p, t)
    return phi, J


def project_positions_out(module, q0, p, t0=0.0, tol=GAP_TOL, max_iter=50):
    """q with g(q, t0) >= -tol max(1, |q0|) (and Phi(q, t0) = 0), nearest q0 in the H metric
    (Gauss-Newton, module docstring). SimulationError naming the deepest contact when the
    iteration cannot get out."""
    from .consistent import mass
    q = np.array(q0, dtype=float)
    bound = tol * max(1.0, float(np.abs(q).max(initial=0.0)))
    for _ in range(max_iter):
        g, WN = contact_gaps(module, q, p, t0)
        phi, J = _holonomic(module, q, p, t0)
        if g.min(initial=np.inf) >= -bound and np.abs(phi).max(initial=0.0) <= bound:
            return q
        # aim a little inside the admissible side so that rounding leaves g >= 0
        dq, _ = metric_projection(mass(module, q, p, t0), WN, g - 0.5 * bound, J, phi)
        q = q + dq
    g, _ = contact_gaps(module, q, p, t0)
    worst = int(np.argmin(g))
    raise SimulationError(
        f"{module.NAME}: q0 = {np.asarray(q0).tolist()} lies inside contact "
        f"{module.CONTACTS[worst]!r} and the projection onto g(q) >= 0 did not get out (gap "
        f"{g[worst]:.3g} after {max_iter} Gauss-Newton steps); give a q0 outside the contacts")


def inelastic_velocity(module, q, v0, p, t0=0.0, tol=GAP_TOL):
    """v nearest v0 in the H(q) metric whose normal velocity does not approach at the closed
    contacts (g <= tol max(1, |q|)): v = v0 + H^-1 W_N^T lam, lam >= 0 (module docstring)."""
    from .consistent import mass
    g, WN = contact_gaps(module, q, p, t0)
    closed = np.flatnonzero(g <= tol * max(1.0, float(np.abs(q).max(initial=0.0))))
    if not closed.size:
        return np.array(v0, dtype=float)
    W = WN[closed]
    u = W @ v0 + normal_bias(module, q, p, t0)[closed]
    phi, J = _holonomic(module, q, p, t0)
    dv, _ = metric_projection(mass(module, q, p, t0), W, u, J, np.zeros(J.shape[0]))
    return v0 + dv


def contact_start(module, q0, v0, p, t0=0.0, penetration="project", stacklevel=2):
    """(q, v) for a contact method: (q0, v0) when no gap is negative; else refused
    (penetration="refuse": ContactPenetration), projected out with one warning
    (penetration="project", the default) or kept with the warning (penetration="keep"; see the
    module docstring). q0, v0 (n,)."""
    if penetration not in PENETRATION_MODES:
        raise SimulationError(f"penetration={penetration!r}: expected one of "
                              f"{', '.join(map(repr, PENETRATION_MODES))}")
    q0, v0 = np.asarray(q0, dtype=float), np.asarray(v0, dtype=float)
    g, _ = contact_gaps(module, q0, p, t0)
    if g.min(initial=np.inf) >= -GAP_TOL * max(1.0, float(np.abs(q0).max(initial=0.0))):
        return q0, v0
    worst = int(np.argmin(g))
    inside = np.flatnonzero(g < 0.0)
    others = f" (and {inside.size - 1} more)" if inside.size > 1 else ""
    where = (f"{module.NAME}: q0 starts inside contact {module.CONTACTS[worst]!r} "
             f"(gap = {g[worst]:.6g} < 0){others}")
    if penetration == "refuse":
        raise ContactPenetration(f"{where}; penetration='refuse': give a q0 with every gap >= 0, "
                                 f"or penetration='project' to move it out")
    if penetration == "keep":
        warnings.warn(f"{where}; kept there (penetration='keep'): the method's own response "
                      f"to a penetration acts, which may launch it", stacklevel=stacklevel)
        return q0, v0
    q = project_positions_out(module, q0, p, t0)
    v = inelastic_velocity(module, q, v0, p, t0)
    dE = float(module.energy(q, v, float(t0), p) - module.energy(q0, v0, float(t0), p))
    warnings.warn(f"{where}; projected onto g(q) >= 0 in the kinetic-energy metric, moving q0 "
                  f"by max|dq| = {np.abs(q - q0).max():.3g} and v0 by max|dv| = "
                  f"{np.abs(v - v0).max():.3g} (energy change {dE:+.3g}, no approach left; "
                  f"penetration='refuse' refuses instead)", stacklevel=stacklevel)
    return np.ascontiguousarray(q), np.ascontiguousarray(v)
