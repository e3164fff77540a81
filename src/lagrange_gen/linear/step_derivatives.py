"""Jacobians of one discrete step of a stepper with respect to the state and the inputs.

    q1, v1, Fx, Gu = step_jacobian(module, "midpoint", h, q, v, u=[0.0])
    # (q1, v1) = step(q, v, u);  d(q1, v1) = Fx d(q, v) + Gu du   (u held over the step)

For a discrete-time controller (e.g. scipy.linalg.solve_discrete_are on Fx, Gu). The step
itself is taken by the method's own jitted code (lagrange_gen.Stepper); its derivatives come from
the exact derivative kernels, differentiating the map that method's module (steppers/methods/<method>.py)
computes, with its kernels at the times it evaluates them:

* explicit_euler: x1 = x + h f(x, t), so d x1 = (I + h df/dx) dx + h df/du du;
* rk4: the chain rule through the stages;
* implicit_euler, midpoint, symplectic_euler, verlet: the implicit function theorem on the
  step's equations at the Newton solution (d unknown = -(dR/d unknown)^-1 dR/d(q, v, u)).
  symplectic_euler and verlet share the kick H(q) u = H(q) v + hk f(q, u, t) (hk = h, h/2).
  On the explicit path of the partitioned methods (constant H, velocity-free forces) the
  implicit equations are linear and the same formulas give that path's Jacobian;
* composition, composition6: the product, over the substeps, of verlet's Jacobians at g_i h
  (the coefficients COEFFS of those modules). Each substep is taken by a verlet Stepper from the
  state and the time at which the composition starts it, and its Jacobian is evaluated at that
  substep's own Newton solutions; substeps with g_i < 0 run backwards in time.

Covered: the fixed-step methods for unconstrained models without nonsmooth elements (METHODS);
dop853 (adaptive) and the methods for constraints or elements are refused. The methods written
in the momentum p = H(q) v (MOMENTUM_FORM) use d(momentum_rate)/du = d rhs/du (input_jacobian),
true when T does not depend on the inputs, and refuse models whose T has a term linear in the
velocities (TRANSPORT: canonical momentum H v + b). Shapes: Fx (2n, 2n), Gu (2n, n_inputs).
"""

from __future__ import annotations

from functools import partial

import numpy as np

from ..errors import SimulationError
from .linearize import accel_jacobians, as_vector, parameter_vector
from ..run.control import input_slots
from ..steppers.core.explicit_rk import RK4_A, RK4_B, RK4_C
from ..steppers.methods import composition, composition6

__all__ = ["step_jacobian", "METHODS"]

#: The methods step_jacobian covers.
METHODS = ("explicit_euler", "symplectic_euler", "verlet", "midpoint", "implicit_euler", "rk4",
           "composition", "composition6")
#: Those whose derivatives here assume the momentum p = H(q) v (no T1 term in T).
MOMENTUM_FORM = ("symplectic_euler", "verlet", "midpoint", "composition", "composition6")


def step_jacobian(module, method, h, q, v, u=None, t=0.0, params=None, **settings):
    """(q1 (n,), v1 (n,), Fx (2n, 2n), Gu (2n, n_inputs)) of one step of ``method`` from
    (q, v) at t with the inputs held at u; ``settings`` as simulate's (e.g. newton_tol)."""
    from ..run.simulate import load_module
    from ..run.stepper import Stepper
    if method not in METHODS:
        raise SimulationError(f"step_jacobian: {method!r} is not covered (covered: "
                              f"{', '.join(METHODS)})")
    module = load_module(module, method=method)
    if method in MOMENTUM_FORM and getattr(module, "TRANSPORT", False):
        others = [m for m in METHODS if m not in MOMENTUM_FORM]
        raise SimulationError(f"step_jacobian: {module.NAME} has a kinetic energy linear in the "
                              f"velocities (canonical momentum H v + b); {method}'s step Jacobian "
                              f"covers p = H v only (use {', '.join(others[:-1])} or {others[-1]})")
    n = module.N_COORDS
    q, v = as_vector(q, n, "q", module), as_vector(v, n, "v", module)
    p = parameter_vector(module, params, u)
    stepper = Stepper(module, method, h, params=p, q0=q, v0=v, t0=t, **settings)
    stepper.step()
    q1, v1 = stepper.q.copy(), stepper.v.copy()
    jac = _JACOBIANS[method](module, float(h), q, v, q1, v1, float(t), p, stepper)
    return (q1, v1) + jac


def _f_jac(module, q, v, t, p):
    """(a, [[0, I, 0], [a_q, a_v, a_u]]) (2n, 2n + k): the first-order system's Jacobian."""
    n, k = module.N_COORDS, input_slots(module)[1]
    a, _, aq, av, au = accel_jacobians(module, q, v, t, p)
    top = np.hstack((np.zeros((n, n)), np.eye(n), np.zeros((n, k))))
    return a, np.vstack((top, np.hstack((aq, av, au))))


def _seed(module):
    """d(q, v)/d(q, v, u) = [I 0] (2n, 2n + k)."""
    n, k = module.N_COORDS, input_slots(module)[1]
    return np.hstack((np.eye(2 * n), np.zeros((2 * n, k))))


def _split(module, d):
    """(Fx, Gu) from d(q1, v1)/d(q, v, u) (2n, 2n + k)."""
    n = module.N_COORDS
    return d[:, :2 * n], d[:, 2 * n:]


def _explicit_euler(module, h, q, v, q1, v1, t, p, stepper):
    """q1 = q + h v, v1 = v + h a(q, v, t): x1 = x + h f(x), d x1 = seed + h F."""
    _, F = _f_jac(module, q, v, t, p)
    return _split(module, _seed(module) + h * F)


def _rk4(module, h, q, v, q1, v1, t, p, stepper):
    """The chain rule through the stages X_i = x + h sum_j A_ij K_j, K_i = f(X_i)."""
    n = module.N_COORDS
    x = np.concatenate((q, v))
    seed = _seed(module)                                        # d x / d(x, u)
    K, dK = [], []
    for i in range(len(RK4_B)):
        X = x + h * sum(RK4_A[i, j] * K[j] for j in range(i))
        dX = seed + h * sum(RK4_A[i, j] * dK[j] for j in range(i))
        a, F = _f_jac(module, X[:n], X[n:], t + RK4_C[i] * h, p)
        K.append(np.concatenate((X[n:], a)))
        dK.append(F[:, :2 * n] @ dX + np.hstack((np.zeros((2 * n, 2 * n)), F[:, 2 * n:])))
    return _split(module, seed + h * sum(b * dk for b, dk in zip(RK4_B, dK)))


def _implicit_euler(module, h, q, v, q1, v1, t, p, stepper):
    """G(x1) = (q1 - q - h v1, v1 - v - h a(q1, v1, u)) = 0 (the step's Newton equations times
    H(q1)^-1: the same solution, so the same derivatives)."""
    n = module.N_COORDS
    _, F = _f_jac(module, q1, v1, t + h, p)
    I = np.eye(n)
    G1 = np.block([[I, -h * I], [-h * F[n:, :n], I - h * F[n:, n:2 * n]]])
    Gu = np.vstack((np.zeros((n, F.shape[1] - 2 * n)), -h * F[n:, 2 * n:]))
    return np.linalg.solve(G1, np.eye(2 * n)), -np.linalg.solve(G1, Gu)


def _kernels(module, q, w, t, p):
    """H(q), D(q; w) = d(H w)/dq, f(q, w), f_q, f_v, f_u for the momentum-form methods."""
    n, k = module.N_COORDS, input_slots(module)[1]
    H, D, f = np.zeros((n, n)), np.zeros((n, n)), np.zeros(n)
    fq, fv, fu = np.zeros((n, n)), np.zeros((n, n)), np.zeros((n, k))
    module.mass_matrix(q, t, np.asarray(p), H)
    module.mass_matvec_dq(q, w, t, p, D)
    module.momentum_rate(q, w, t, p, f)
    module.momentum_rate_jacobian(q, w, t, p, fq, fv)
    if k:
        module.input_jacobian(q, w, t, p, fu)
    return H, D, f, fq, fv, fu


def _rows(module):
    """(d q/d(q, v, u) = [I 0 0] (n, 2n + k), d u_in/d(q, v, u) = [0 0 I] (k, 2n + k))."""
    n, k = module.N_COORDS, input_slots(module)[1]
    dqx = np.hstack((np.eye(n), np.zeros((n, n + k))))
    dux = np.hstack((np.zeros((k, 2 * n)), np.eye(k)))
    return dqx, dux


def _midpoint(module, h, q, v, q1, v1, t, p, stepper):
    """R(vb) = H(qb) vb - h/2 f(qb, vb) - H(q) v = 0, qb = q + h/2 vb; q1 = q + h vb,
    p1 = H(q) v + h f(qb, vb), v1 = H(q1)^-1 p1 (f at t + h/2)."""
    vb = (q1 - q) / h
    qb = q + 0.5 * h * vb
    H0, D0, *_ = _kernels(module, q, v, t, p)
    Hb, Db, _, fq, fv, fu = _kernels(module, qb, vb, t + 0.5 * h, p)
    dqx, dux = _rows(module)
    dp = np.hstack((D0, H0, np.zeros_like(fu)))                  # d p / d(q, v, u)
    dR_dvb = Hb + 0.5 * h * Db - 0.25 * h * h * fq - 0.5 * h * fv
    dR_dx = (Db - 0.5 * h * fq) @ dqx - dp - 0.5 * h * fu @ dux
    dvb = -np.linalg.solve(dR_dvb, dR_dx)
    dq1 = dqx + h * dvb
    dqb = dqx + 0.5 * h * dvb
    dp1 = dp + h * (fq @ dqb + fv @ dvb + fu @ dux)
    return _velocity(module, q1, v1, t + h, p, dq1, dp1)


def _velocity(module, q1, v1, t1, p, dq1, dp1):
    """(Fx, Gu) from dq1 and dp1 (rows of d/d(q, v, u)), v1 = H(q1, t1)^-1 p1."""
    H1, D1, *_ = _kernels(module, q1, v1, t1, p)
    dv1 = np.linalg.solve(H1, dp1 - D1 @ dq1)
    return _split(module, np.vstack((dq1, dv1)))


def _kick(module, hk, q, v, u, t, p):
    """The kick H(q) u = H(q) v + hk f(q, u, t) (symplectic_euler: hk = h; verlet: h/2) at its
    solution u: (du, d(H(q) u)) as rows of d/d(q, v, u_in)."""
    dqx, dux = _rows(module)
    H0, D0v, *_ = _kernels(module, q, v, t, p)
    _, D0u, _, fq0, fv0, fu0 = _kernels(module, q, u, t, p)
    dp = np.hstack((D0v, H0, np.zeros_like(fu0)))               # d(H(q) v)
    du = np.linalg.solve(H0 - hk * fv0, dp - (D0u - hk * fq0) @ dqx + hk * fu0 @ dux)
    return du, D0u @ dqx + H0 @ du


def _newton_path(module, stepper):
    """True when the partitioned method took its Newton path (options.explicit_path is false),
    so its workspace holds the Newton solutions."""
    return not (module.MASS_IS_CONSTANT and module.FORCES_VELOCITY_FREE
                and not stepper.settings.newton_always)


def _symplectic_euler(module, h, q, v, q1, v1, t, p, stepper):
    """H(q) u = H(q) v + h f(q, u, t); q1 = q + h u, p1 = H(q) u, v1 = H(q1)^-1 p1 (at t + h).
    u is the step's Newton solution (its workspace); on the explicit path (v1 = v + h a,
    q1 = q + h v1) u = v1."""
    u = np.array(stepper.ws.u) if _newton_path(module, stepper) else v1
    dqx, _ = _rows(module)
    du, dp1 = _kick(module, h, q, v, u, t, p)
    return _velocity(module, q1, v1, t + h, p, dqx + h * du, dp1)


def _verlet(module, h, q, v, q1, v1, t, p, stepper):
    """H(q) u = H(q) v + h/2 f(q, u, t); H(q1) w = H(q) u, q1 = q + h/2 (u + w);
    p1 = H(q) u + h/2 f(q1, w, t + h), v1 = H(q1)^-1 p1. u and w are the step's own
    Newton solutions (its workspace); on the explicit path w = u."""
    ws = stepper.ws
    uu = np.array(ws.u)
    w = np.array(ws.w) if _newton_path(module, stepper) else uu
    dqx, dux = _rows(module)
    du, dps = _kick(module, 0.5 * h, q, v, uu, t, p)
    H1, D1w, _, fq1, fv1, fu1 = _kernels(module, q1, w, t + h, p)
    dw = np.linalg.solve(H1 + 0.5 * h * D1w, dps - D1w @ (dqx + 0.5 * h * du))
    dq1 = dqx + 0.5 * h * (du + dw)
    dp1 = dps + 0.5 * h * (fq1 @ dq1 + fv1 @ dw + fu1 @ dux)
    return _velocity(module, q1, v1, t + h, p, dq1, dp1)


def _composition(coeffs, module, h, q, v, q1, v1, t, p, stepper):
    """Psi_h = V_{g_s h} o ... o V_{g_1 h} (composition.composed_step): the product of
    _verlet's Jacobians, substep i taken by a verlet Stepper from (q_i, v_i) at t_i, the time
    composed_step starts it (t_sub += g h). Stepper takes h > 0 only, so a backward substep
    (g < 0) sets its step after construction (prepare does not depend on h)."""
    from ..run.stepper import Stepper
    Fx, Gu = _split(module, _seed(module))
    qi, vi, ti = q, v, t
    settings = stepper.settings._asdict()
    for g in coeffs:
        sub = Stepper(module, "verlet", abs(g * h), params=p, q0=qi, v0=vi, t0=ti, **settings)
        sub.h = g * h
        sub.step()
        qn, vn = sub.q.copy(), sub.v.copy()
        F, G = _verlet(module, g * h, qi, vi, qn, vn, ti, p, sub)
        Fx, Gu = F @ Fx, F @ Gu + G
        qi, vi = qn, vn
        ti += g * h
    return Fx, Gu


_JACOBIANS = {"explicit_euler": _explicit_euler, "symplectic_euler": _symplectic_euler,
              "verlet": _verlet, "midpoint": _midpoint, "implicit_euler": _implicit_euler,
              "rk4": _rk4, "composition": partial(_composition, composition.COEFFS),
              "composition6": partial(_composition, composition6.COEFFS)}
