"""Jacobians of one discrete step of a stepper with respect to the state and the inputs.

    q1, v1, Fx, Gu = step_jacobian(module, "midpoint", h, q, v, u=[0.0])
    # (q1, v1) = step(q, v, u);  d(q1, v1) = Fx d(q, v) + Gu du   (u held over the step)

For a discrete-time controller (e.g. scipy.linalg.solve_discrete_are on Fx, Gu). The step
itself is taken by the method's own jitted code (lagrange_gen.Stepper); its derivatives come from
the exact derivative kernels: through the stages by the chain rule for rk4, and by the implicit
function theorem on the step's equations for the implicit methods, differentiated at the
Newton solution (d unknown = -(dR/d unknown)^-1 dR/d(q, v, u)). Covered: rk4, implicit_euler,
midpoint, verlet, on unconstrained models without elements. The methods written in the momentum
p = H(q) v (midpoint, verlet) use d(momentum_rate)/du = d rhs/du (input_jacobian), true when T
does not depend on the inputs. Shapes: Fx (2n, 2n), Gu (2n, n_inputs).
"""

from __future__ import annotations

import numpy as np

from .control import input_slots
from .errors import SimulationError
from .linearization import _accel_jacobians, _vec, parameter_vector
from .steppers.explicit_rk import RK4_A, RK4_B, RK4_C

__all__ = ["step_jacobian", "METHODS"]

#: The methods step_jacobian covers.
METHODS = ("rk4", "implicit_euler", "midpoint", "verlet")
#: Those whose derivatives here assume the momentum p = H(q) v (no T1 term in T).
MOMENTUM_FORM = ("midpoint", "verlet")


def step_jacobian(module, method, h, q, v, u=None, t=0.0, params=None, **settings):
    """(q1 (n,), v1 (n,), Fx (2n, 2n), Gu (2n, n_inputs)) of one step of ``method`` from
    (q, v) at t with the inputs held at u; ``settings`` as simulate's (e.g. newton_tol)."""
    from .simulation import load_module
    from .stepper_api import Stepper
    if method not in METHODS:
        raise SimulationError(f"step_jacobian: {method!r} is not covered (covered: "
                              f"{', '.join(METHODS)})")
    module = load_module(module, method=method)
    if method in MOMENTUM_FORM and getattr(module, "TRANSPORT", False):
        raise SimulationError(f"step_jacobian: {module.NAME} has a kinetic energy linear in the "
                              f"velocities (canonical momentum H v + b); {method}'s step Jacobian "
                              "covers p = H v only (use rk4 or implicit_euler)")
    n = module.N_COORDS
    q, v = _vec(q, n, "q", module), _vec(v, n, "v", module)
    p = parameter_vector(module, params, u)
    stepper = Stepper(module, method, h, params=p, q0=q, v0=v, t0=t, **settings)
    stepper.step()
    q1, v1 = stepper.q.copy(), stepper.v.copy()
    jac = _JACOBIANS[method](module, float(h), q, v, q1, v1, float(t), p, stepper)
    return (q1, v1) + jac


def _f_jac(module, q, v, t, p):
    """(a, [[0, I, 0], [a_q, a_v, a_u]]) (2n, 2n + k): the first-order system's Jacobian."""
    n, k = module.N_COORDS, input_slots(module)[1]
    a, _, aq, av, au = _accel_jacobians(module, q, v, t, p)
    top = np.hstack((np.zeros((n, n)), np.eye(n), np.zeros((n, k))))
    return a, np.vstack((top, np.hstack((aq, av, au))))


def _rk4(module, h, q, v, q1, v1, t, p, stepper):
    """The chain rule through the stages X_i = x + h sum_j A_ij K_j, K_i = f(X_i)."""
    n, k = module.N_COORDS, input_slots(module)[1]
    x = np.concatenate((q, v))
    seed = np.hstack((np.eye(2 * n), np.zeros((2 * n, k))))     # d x / d(x, u)
    K, dK = [], []
    for i in range(len(RK4_B)):
        X = x + h * sum(RK4_A[i, j] * K[j] for j in range(i))
        dX = seed + h * sum(RK4_A[i, j] * dK[j] for j in range(i))
        a, F = _f_jac(module, X[:n], X[n:], t + RK4_C[i] * h, p)
        K.append(np.concatenate((X[n:], a)))
        dK.append(F[:, :2 * n] @ dX + np.hstack((np.zeros((2 * n, 2 * n)), F[:, 2 * n:])))
    d = seed + h * sum(b * dk for b, dk in zip(RK4_B, dK))
    return d[:, :2 * n], d[:, 2 * n:]


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


def _midpoint(module, h, q, v, q1, v1, t, p, stepper):
    """R(vb) = H(qb) vb - h/2 f(qb, vb) - H(q) v = 0, qb = q + h/2 vb; q1 = q + h vb,
    p1 = H(q) v + h f(qb, vb), v1 = H(q1)^-1 p1 (f at t + h/2)."""
    n = module.N_COORDS
    vb = (q1 - q) / h
    qb = q + 0.5 * h * vb
    H0, D0, *_ = _kernels(module, q, v, t, p)
    Hb, Db, _, fq, fv, fu = _kernels(module, qb, vb, t + 0.5 * h, p)
    dp = np.hstack((D0, H0, np.zeros_like(fu)))                  # d p / d(q, v, u)
    dqx = np.hstack((np.eye(n), np.zeros((n, n)), np.zeros_like(fu)))
    dR_dvb = Hb + 0.5 * h * Db - 0.25 * h * h * fq - 0.5 * h * fv
    dR_dx = (Db - 0.5 * h * fq) @ dqx - dp - 0.5 * h * np.hstack((np.zeros((n, 2 * n)), fu))
    dvb = -np.linalg.solve(dR_dvb, dR_dx)
    dq1 = dqx + h * dvb
    dqb = dqx + 0.5 * h * dvb
    dp1 = dp + h * (fq @ dqb + fv @ dvb + np.hstack((np.zeros((n, 2 * n)), fu)))
    return _velocity(module, q1, v1, p, dq1, dp1)


def _velocity(module, q1, v1, p, dq1, dp1):
    """Rows of d(q1, v1)/d(q, v, u) from dq1 and dp1, v1 = H(q1)^-1 p1; split (Fx, Gu)."""
    n = module.N_COORDS
    H1, D1, *_ = _kernels(module, q1, v1, 0.0, p)
    dv1 = np.linalg.solve(H1, dp1 - D1 @ dq1)
    d = np.vstack((dq1, dv1))
    return d[:, :2 * n], d[:, 2 * n:]


def _verlet(module, h, q, v, q1, v1, t, p, stepper):
    """H(q) u = H(q) v + h/2 f(q, u, t); H(q1) w = H(q) u, q1 = q + h/2 (u + w);
    p1 = H(q) u + h/2 f(q1, w, t + h), v1 = H(q1)^-1 p1. u and w are the step's own
    Newton solutions (its workspace); on the explicit path w = u."""
    n = module.N_COORDS
    ws = stepper._core.ws
    uu = np.array(ws.u)
    w = np.array(ws.w) if not (module.MASS_IS_CONSTANT and module.FORCES_VELOCITY_FREE
                               and not stepper.settings.newton_always) else uu
    H0, D0v, *_ = _kernels(module, q, v, t, p)
    _, D0u, _, fq0, fv0, fu = _kernels(module, q, uu, t, p)
    H1, D1w, _, fq1, fv1, fu1 = _kernels(module, q1, w, t + h, p)
    zu = np.zeros_like(fu)
    dqx = np.hstack((np.eye(n), np.zeros((n, n)), zu))
    dux = np.hstack((np.zeros((fu.shape[1], 2 * n)), np.eye(fu.shape[1])))
    dp = np.hstack((D0v, H0, zu))
    du = np.linalg.solve(H0 - 0.5 * h * fv0, dp - (D0u - 0.5 * h * fq0) @ dqx + 0.5 * h * fu @ dux)
    dps = D0u @ dqx + H0 @ du
    dw = np.linalg.solve(H1 + 0.5 * h * D1w, dps - D1w @ (dqx + 0.5 * h * du))
    dq1 = dqx + 0.5 * h * (du + dw)
    dp1 = dps + 0.5 * h * (fq1 @ dq1 + fv1 @ dw + fu1 @ dux)
    return _velocity(module, q1, v1, p, dq1, dp1)


_JACOBIANS = {"rk4": _rk4, "implicit_euler": _implicit_euler, "midpoint": _midpoint,
              "verlet": _verlet}
