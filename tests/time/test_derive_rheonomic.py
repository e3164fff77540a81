"""The rheonomic derivation (T = T2 + T1 + T0, V(q, t), Phi(q, t)) against Lagrange's equations
written out in plain sympy: q_i -> q_i(t) functions, d/dt(dL/dqd) - dL/dq by sympy's own diff
of the composed expression, never through lagrange_gen.derive. Random models mix division,
powers, sin and exp of t, and velocity-linear (gyroscopic) terms."""

import numpy as np
import pytest
import sympy as sp

from lagrange_gen import Model, coordinates, parameters, t
from lagrange_gen.derive import derive


def lagrange_reference(q, T, V, Q, Phi):
    """(H, rhs, E, Phi_t, gamma) of L = T - V by sympy alone: H qdd = rhs from
    d/dt dL/dqd - dL/dq = Q with q(t) functions, E = qd . dL/dqd - L, and the second time
    derivative of Phi along q(t), J qdd = gamma."""
    n = len(q)
    qd = [c.d for c in q]
    qdd = sp.symbols(f"qdd0:{n}")
    f = [sp.Function(f"f{i}")(t) for i in range(n)]
    to_f = {**{qd[i]: f[i].diff(t) for i in range(n)}, **{q[i]: f[i] for i in range(n)}}

    def back(expr):
        expr = expr.subs({f[i].diff(t, 2): qdd[i] for i in range(n)})
        expr = expr.subs({f[i].diff(t): qd[i] for i in range(n)})
        return expr.subs({f[i]: q[i] for i in range(n)})
    L = T - V
    EL = [back(sp.diff(sp.diff(L, qd[i]).xreplace(to_f), t)) - sp.diff(L, q[i]) - Q[i] for i in range(n)]
    H = sp.Matrix(n, n, lambda i, j: sp.diff(EL[i], qdd[j]))
    rhs = sp.Matrix([-e.subs({a: 0 for a in qdd}) for e in EL])
    E = sum(qd[i] * sp.diff(L, qd[i]) for i in range(n)) - L
    Phi_t = sp.Matrix([sp.diff(c, t) for c in Phi])
    gamma = sp.Matrix([-back(sp.diff(c.xreplace(to_f), t, 2)).subs({a: 0 for a in qdd}) for c in Phi])
    return H, rhs, E, Phi_t, gamma


def random_model(seed):
    """A random 2-coordinate rheonomic model with one rheonomic constraint."""
    rng = np.random.default_rng(seed)
    x, y = coordinates("x y")
    k, c, w = parameters("k c w", defaults=(1.3, 0.4, 2.1))
    pick = lambda options: options[rng.integers(len(options))]   # noqa: E731
    time_fns = [sp.sin(w * t), sp.exp(-t / 3), 1 / (2 + sp.cos(t)), t**2 / (1 + t**2), sp.cos(t)**3]
    q_fns = [sp.cos(x), sp.sin(y) ** 2, 1 / (2 + sp.sin(x * y)), x * y, sp.exp(-y**2)]
    a11 = 2 + pick(q_fns) ** 2 + pick(time_fns) ** 2
    a22 = 3 + (pick(q_fns) + pick(time_fns)) ** 2
    a12 = pick(q_fns) * pick(time_fns) / 2
    b = [pick(q_fns) * pick(time_fns), pick(q_fns) + pick(time_fns) * y]
    T2 = (a11 * x.d**2 + 2 * a12 * x.d * y.d + a22 * y.d**2) / 2
    T = T2 + b[0] * x.d + b[1] * y.d + pick(q_fns) * pick(time_fns) ** 2
    V = k * (x**2 + y**2) / 2 + pick(q_fns) * pick(time_fns)
    forces = [c * pick(time_fns) * y.d, -c * x.d]
    Phi = [x - y * pick(time_fns) - pick(q_fns) / 5]
    model = Model(f"rheonomic_{seed}", coords=[x, y], T=T, V=V, forces=forces, constraints=Phi,
                  dissipation=c * x.d**2 / 2)
    Q = [forces[0] - c * x.d, forces[1]]
    return model, (x, y), T, V, Q, Phi


@pytest.mark.parametrize("seed", range(6))
def test_rheonomic_derivation_matches_plain_lagrange(seed):
    model, q, T, V, Q, Phi = random_model(seed)
    dyn = derive(model)
    H, rhs, E, Phi_t, gamma = lagrange_reference(list(q), T, V, Q, Phi)
    args = [*q, *(c.d for c in q), t, *model.params]
    ours = sp.lambdify(args, [dyn.H, dyn.rhs, dyn.E, dyn.Phi_t, dyn.gamma])
    ref = sp.lambdify(args, [H, rhs, E, Phi_t, gamma])
    rng = np.random.default_rng(100 + seed)
    for _ in range(5):
        point = [*rng.uniform(-1.5, 1.5, 4), rng.uniform(0, 3), 1.3, 0.4, 2.1]
        for got, want, name in zip(ours(*point), ref(*point), ("H", "rhs", "E", "Phi_t", "gamma")):
            np.testing.assert_allclose(np.asarray(got, float), np.asarray(want, float),
                                       rtol=1e-10, atol=1e-10, err_msg=f"seed {seed}: {name}")


def test_scleronomic_energy_is_T_plus_V_and_hoop_energy_is_jacobi():
    x, th = coordinates("x th")
    m, w = parameters("m w", defaults=(1.0, 2.0))
    plain = derive(Model("plain", coords=[x], T=m * x.d**2 / 2, V=x**2))
    assert sp.simplify(plain.E - (m * x.d**2 / 2 + x**2)) == 0
    hoop = derive(Model("hoop", coords=[th], T=m * (th.d**2 + w**2 * sp.sin(th)**2) / 2,
                        V=-sp.cos(th)))
    assert sp.simplify(hoop.E - (m * th.d**2 / 2 - m * w**2 * sp.sin(th)**2 / 2 - sp.cos(th))) == 0


@pytest.mark.parametrize("seed", range(3))
def test_rheonomic_newton_jacobians_match_plain_lagrange(seed):
    """drhs/dq, drhs/dqd (with dH/dt qd in h), the canonical momentum p = dL/dqd (as
    H qd + b), its rate dp/dt = dL/dq + Q by Lagrange's equations, and that rate's Jacobians,
    against sympy's jacobian of the reference."""
    model, q, T, V, Q, Phi = random_model(seed)
    dyn = derive(model)
    H, rhs, *_ = lagrange_reference(list(q), T, V, Q, Phi)
    qd = sp.Matrix([c.d for c in q])
    L = T - V
    mom = sp.Matrix([sp.diff(L, c) + Qi for c, Qi in zip(q, Q)])
    p_can = sp.Matrix([sp.diff(L, v) for v in qd])
    want = [rhs.jacobian(q), rhs.jacobian(qd), mom.jacobian(q), mom.jacobian(qd), mom, p_can]
    got = [dyn.jac[k] for k in ("drhs_dq", "drhs_dqd", "dmom_dq", "dmom_dqd")]
    got += [dyn.momentum_rate, dyn.H * qd + dyn.b]
    args = [*q, *qd, t, *model.params]
    f_got, f_want = sp.lambdify(args, got), sp.lambdify(args, want)
    rng = np.random.default_rng(200 + seed)
    for _ in range(4):
        point = [*rng.uniform(-1.5, 1.5, 4), rng.uniform(0, 3), 1.3, 0.4, 2.1]
        for a, b, name in zip(f_got(*point), f_want(*point), ("drhs_dq", "drhs_dqd", "dmom_dq", "dmom_dqd")):
            np.testing.assert_allclose(np.asarray(a, float), np.asarray(b, float), rtol=1e-9,
                                       atol=1e-9, err_msg=f"seed {seed}: {name}")
