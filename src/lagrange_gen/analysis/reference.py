"""Right-hand sides and reference solutions for scipy's solve_ivp, built on a generated module.

The first-order state is y = (q, v) (2n,). ``ode_rhs`` is y' = (v, H^-1 rhs) through the generated
forward_dynamics; ``ode_jacobian`` is its exact Jacobian from the generated rhs_jacobian and
mass_matvec_dq (what Radau and BDF need to be fair); ``kkt_rhs`` is the acceleration-level
(index-1) form of a constrained model, [[H, J^T], [J, 0]] (qdd, -lam) = (rhs, gamma), which is
what a user of solve_ivp integrates and which drifts off Phi = 0.

A reference is DOP853 at rtol = atol = 1e-13 and is only trusted after a second, different solver
agrees with it (``check_reference``): Radau with the exact Jacobian, or for the Cartesian
pendulum the same motion integrated in one angle. At the end: the same right-hand side derived
independently by sympy.physics.mechanics (``mechanics_rhs``), and the closed-form solutions of
the hard cases (damped oscillator, pendulum near the separatrix, FPU energies).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp
from scipy.special import ellipj

from ..steppers.core.status import OK

REF_TOL = 1e-13
FPU_OMEGA = 50.0
#: HARD_CASES case 5 (Hairer-Lubich-Wanner, DOP853 at 1e-13): I_j at t = 50, 100, 200.
FPU_REFERENCE = {50.0: (0.559, 0.367, 0.070), 100.0: (0.106, 0.421, 0.476),
                 200.0: (0.010, 0.160, 0.835)}
SEPARATRIX_K = 0.999


def ode_rhs(mod, p):
    """f(t, y) -> y' (2n,) for solve_ivp; raises when H(q) is singular (never returns NaN)."""
    n = mod.N_COORDS
    H, qdd = np.empty((n, n)), np.empty(n)

    def f(t, y):
        if mod.forward_dynamics(y[:n], y[n:], t, p, H, qdd) != OK:
            raise FloatingPointError(f"{mod.NAME}: singular mass matrix at q = {y[:n]}")
        return np.concatenate((y[n:], qdd))
    return f


def ode_jacobian(mod, p):
    """J(t, y) (2n, 2n) of ode_rhs: with H qdd = rhs(q, v),
    d qdd/dq = H^-1 (d rhs/dq - d(H w)/dq |_{w = qdd}) and d qdd/dv = H^-1 d rhs/dv."""
    n = mod.N_COORDS
    H, qdd = np.empty((n, n)), np.empty(n)
    Jq, Jv, dHw = np.empty((n, n)), np.empty((n, n)), np.empty((n, n))

    def jac(t, y):
        q, v = y[:n], y[n:]
        mod.dynamics(q, v, t, p, H, qdd)
        Hm = H.copy()
        qdd_ = np.linalg.solve(Hm, qdd)
        mod.rhs_jacobian(q, v, t, p, Jq, Jv)
        mod.mass_matvec_dq(q, qdd_, t, p, dHw)
        out = np.zeros((2 * n, 2 * n))
        out[:n, n:] = np.eye(n)
        out[n:, :n] = np.linalg.solve(Hm, Jq - dHw)
        out[n:, n:] = np.linalg.solve(Hm, Jv)
        return out
    return jac


def kkt_rhs(mod, p):
    """Index-1 form of a constrained model: y' = (v, qdd) with qdd, lam from the KKT system
    [[H, -J^T], [J, 0]] (qdd, lam) = (rhs, gamma) (m = N_CONSTRAINTS multipliers)."""
    n, m = mod.N_COORDS, mod.N_CONSTRAINTS
    H, rhs = np.empty((n, n)), np.empty(n)
    phi, J, gamma = np.empty(m), np.empty((m, n)), np.empty(m)

    def f(t, y):
        q, v = y[:n], y[n:]
        mod.dynamics(q, v, t, p, H, rhs)
        mod.constraints(q, v, t, p, phi, J, gamma)
        K = np.block([[H, -J.T], [J, np.zeros((m, m))]])
        sol = np.linalg.solve(K, np.concatenate((rhs, gamma)))
        return np.concatenate((v, sol[:n]))
    return f


def constraint_residuals(mod, p, q, v=None):
    """max_i |Phi_i(q)| and max_i |(J v)_i| per row of q, v (S, n) -> two (S,) arrays (the
    second is zeros when v is None)."""
    m, n = mod.N_CONSTRAINTS, mod.N_COORDS
    phi, J, gamma = np.empty(m), np.empty((m, n)), np.empty(m)
    out_phi, out_jv = np.zeros(len(q)), np.zeros(len(q))
    for i, qi in enumerate(q):
        vi = np.zeros(n) if v is None else np.ascontiguousarray(v[i])
        mod.constraints(np.ascontiguousarray(qi), vi, 0.0, p, phi, J, gamma)   # scleronomic models
        if m:
            out_phi[i] = np.max(np.abs(phi))
            out_jv[i] = np.max(np.abs(J @ vi))
    return out_phi, out_jv


def constraint_residual(mod, p, q):
    """max |Phi(q)| over the rows of q (S, n) -> (S,)."""
    return constraint_residuals(mod, p, q)[0]


@dataclass
class Reference:
    """A dense reference solution: ``y_at(t)`` (2n, len(t)); ``y_end`` (2n,) the state at t_end
    (the solver's own end point, not an interpolant); ``agreement`` the max-norm difference to
    the second solver over the sample times; ``second`` names it."""

    sol: object
    y_end: np.ndarray
    agreement: float
    second: str

    def y_at(self, t):
        return self.sol(np.asarray(t, dtype=float))


def solve(f, y0, t_end, method="DOP853", rtol=REF_TOL, atol=REF_TOL, jac=None, t_eval=None):
    """solve_ivp with dense output; raises RuntimeError when the solver fails."""
    kwargs = {"jac": jac} if jac is not None else {}
    sol = solve_ivp(f, (0.0, t_end), y0, method=method, rtol=rtol, atol=atol,
                    dense_output=True, t_eval=t_eval, **kwargs)
    if not sol.success:
        raise RuntimeError(f"reference solver {method} failed: {sol.message}")
    return sol


def ode_reference(mod, p, q0, v0, t_end, t_check, second="Radau"):
    """DOP853 reference of an unconstrained model, checked at t_check (and t_end) against
    ``second``: "Radau" (implicit Runge-Kutta) or "LSODA" (multistep, much cheaper at 1e-13),
    both with the exact Jacobian."""
    y0 = np.concatenate((q0, v0))
    f = ode_rhs(mod, p)
    f(0.0, y0)                   # numba specializes forward_dynamics on the first call
    main = solve(f, y0, t_end)
    other = solve(f, y0, t_end, method=second, jac=ode_jacobian(mod, p))
    diff = max(np.max(np.abs(main.sol(t_check) - other.sol(t_check))),
               np.max(np.abs(main.y[:, -1] - other.y[:, -1])))
    return Reference(main.sol, main.y[:, -1], float(diff), f"{second} at rtol {REF_TOL:g}")


def pendulum_angle_reference(mod, p, q0, v0, t_end, t_check):
    """Reference of the Cartesian pendulum (coords x, y; params m, l, g; |x| = l): DOP853 on the
    same motion in the angle theta from the downward vertical, theta'' = -(g/l) sin(theta),
    mapped to (x, y) = l (sin, -cos); checked against DOP853 on the index-1 Cartesian form."""
    pv = dict(zip(mod.PARAMS, p))
    l, g = pv["l"], pv["g"]
    th0 = np.arctan2(q0[0], -q0[1])
    w0 = (q0[0] * v0[1] - q0[1] * v0[0]) / l**2     # (r x v)_z / l^2
    ang = solve(lambda t, y: np.array([y[1], -g / l * np.sin(y[0])]), np.array([th0, w0]), t_end)

    def cart(t):
        th, w = ang.sol(np.asarray(t, dtype=float))
        return np.array([l * np.sin(th), -l * np.cos(th), l * np.cos(th) * w, l * np.sin(th) * w])
    other = solve(kkt_rhs(mod, p), np.concatenate((q0, v0)), t_end)
    diff = max(np.max(np.abs(cart(t_check) - other.sol(t_check))),
               np.max(np.abs(cart(t_end) - other.y[:, -1])))
    return Reference(cart, cart(t_end), float(diff), "index-1 Cartesian form, DOP853")


# ---------------------------------------------------------------- sympy.physics.mechanics
# The same equations derived a second, independent way: LagrangesMethod on the model's own
# L = T - V (conservative, unconstrained models). The precision suite times it as a peer (what
# PyDy's default "lambdify" generator does); the tests compare it with ode_rhs.

def _symbols_for(model):
    """The model's coordinates as dynamicsymbols, and the substitution Coordinate -> q(t),
    Velocity -> q(t)'."""
    from sympy.physics import mechanics as me
    qs = me.dynamicsymbols(" ".join(c.name for c in model.coords))
    qs = list(qs) if isinstance(qs, (list, tuple)) else [qs]
    subs = {c.d: q.diff() for c, q in zip(model.coords, qs)}
    subs.update({c: q for c, q in zip(model.coords, qs)})
    return qs, subs


def mechanics_equations(model_file):
    """sympy.physics.mechanics LagrangesMethod on L = T - V of a conservative, unconstrained
    model file: returns (mass_matrix_full (2n, 2n), forcing_full (2n,), q(t) list, parameter
    symbols in the model's order). Raises ValueError for a model this peer does not cover."""
    from sympy.physics import mechanics as me

    from ..model.model_file import load_model
    model = load_model(model_file)
    if model.constraints or model.elements or any(f != 0 for f in model.forces) \
            or model.dissipation != 0:
        raise ValueError(f"{model.name}: the sympy.mechanics peer covers conservative "
                         f"unconstrained models only")
    qs, subs = _symbols_for(model)
    lm = me.LagrangesMethod((model.T - model.V).xreplace(subs), qs)
    lm.form_lagranges_equations()
    return lm.mass_matrix_full, lm.forcing_full, qs, list(model.params)


def _plain_symbols(exprs, qs):
    """Replace q(t)' and q(t) by plain symbols (for lambdify); returns (exprs, states)."""
    import sympy as sp
    qd = [sp.Symbol(f"{q.func.__name__}_d") for q in qs]
    qq = [sp.Symbol(f"{q.func.__name__}_q") for q in qs]
    rep = {q.diff(): s for q, s in zip(qs, qd)}
    out = [e.xreplace(rep).xreplace(dict(zip(qs, qq))) for e in exprs]
    return out, qq + qd


def mechanics_rhs(model_file, param_names, p):
    """rhs(t, y) -> y' (2n,) of the sympy.mechanics equations with parameters p (n_params,) in
    param_names order: y' = M^-1 F per call, M and F lambdified to numpy."""
    import sympy as sp
    M, F, qs, params = mechanics_equations(model_file)
    (M, F), states = _plain_symbols([M, F], qs)
    by_name = {s.name: s for s in params}
    psyms = [by_name[name] for name in param_names]
    fM = sp.lambdify([states, psyms], M, "numpy")
    fF = sp.lambdify([states, psyms], F, "numpy")
    pv = list(p)

    def f(t, y):
        return np.linalg.solve(np.asarray(fM(y, pv), dtype=float),
                               np.asarray(fF(y, pv), dtype=float).ravel())
    return f

# ---------------------------------------------------------------- closed forms of the hard cases

def separatrix_exact(t, k=SEPARATRIX_K):
    """theta(t), theta'(t) (each (S,)): sin(theta/2) = k sn(t, k^2), theta' = 2 k cn(t, k^2)."""
    sn, cn, _, _ = ellipj(np.asarray(t, dtype=float), k**2)
    return 2 * np.arcsin(k * sn), 2 * k * cn


def oscillator_exact(t, m, c, b, x0=1.0, v0=0.0):
    """Underdamped m x'' + b x' + x / c = 0: x(t), v(t) (each (S,))."""
    t = np.asarray(t, dtype=float)
    beta = b / (2 * m)
    wd = math.sqrt(1 / (m * c) - beta**2)
    A, B = x0, (v0 + beta * x0) / wd
    e = np.exp(-beta * t)
    x = e * (A * np.cos(wd * t) + B * np.sin(wd * t))
    v = -beta * x + e * wd * (-A * np.sin(wd * t) + B * np.cos(wd * t))
    return x, v


def fpu_oscillatory_energies(q, v, omega=FPU_OMEGA):
    """I_j = (xdot_j^2 + omega^2 x_j^2) / 2 with x_j = (q_2j - q_2j-1) / sqrt 2 for q, v (S, 6):
    returns (S, 3)."""
    r = math.sqrt(2.0)
    x = (q[:, 1::2] - q[:, 0::2]) / r
    xd = (v[:, 1::2] - v[:, 0::2]) / r
    return 0.5 * (xd**2 + omega**2 * x**2)
