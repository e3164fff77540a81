"""The reference: every kernel quantity written from Lagrange's equations directly in plain sympy
(hessian, diff, jacobian, lambdify), from a DrawnModel's raw ingredients. It never imports
lagrange_gen.derive or codegen, so a derivation or printing error cannot hide in both.

    d/dt dT/dqd - dT/dq + dV/dq = Q - dD/dqd + J^T lam
    H = d2T/dqd2,  d/dt dT/dqd = H qdd + (d(dT/dqd)/dq) qd
    rhs = Q - dD/dqd - ((d(dT/dqd)/dq) qd - dT/dq) - dV/dq,   so that H qdd = rhs
    momentum_rate = dT/dq - dV/dq + Q - dD/dqd  (dp/dt for p = dT/dqd)

Shapes for n coordinates, m constraints, ne elements: H (n, n), vectors (n,), Jacobians (n, n),
Phi (m,), J (m, n), gamma (m,), dJw_dq (m, n), s (ne,), G (ne, n), coef (ne, 3); for c contacts
contact_gap (c,), contact_WN = d gap/dq (c, n), contact_WT = d slip/d qd (c, n), contact_coef
(c, 2) = (restitution, friction); for r velocity constraints c = A qd + b: nh_A (r, n), nh_b,
nh_gamma (r,) with A qdd = gamma = -(dc/dq qd + dc/dt), and their derivatives nh_dAw = d(A w)/dq,
nh_dATmu = d(A^T mu)/dq, nh_dc = dc/dq, nh_dgamma_dq, nh_dgamma_dqd; gamma_dq, gamma_dqd (m, n)
of the holonomic gamma.
"""

from __future__ import annotations

import numpy as np
import sympy as sp

from lagrange_gen import t

# lambdify's numpy printer knows Abs, sign, atan2, ...; DiracDelta (from d sign/dx) is zero away
# from the kink, where every sampled state lies.
_MODULES = [{"DiracDelta": lambda *args: 0.0}, "numpy"]
#: sympy leaves d floor(x)/dx unevaluated: zero away from the integers, where sampled states lie.
_PIECEWISE_CONSTANT = (sp.floor, sp.ceiling)


def _jumps_settled(expr):
    """``expr`` (a sympy expression or matrix) with the derivatives of floor and ceiling at 0."""
    return expr.replace(lambda e: isinstance(e, sp.Derivative) and isinstance(e.expr, _PIECEWISE_CONSTANT),
                        lambda e: sp.S.Zero)


_ELEMENT_KIND = {"saint_venant": 0, "dry_friction": 1}
#: Column quantities returned as 1-D arrays, like the kernels' vector outputs.
VECTORS = {"rhs", "momentum_rate", "forces", "dT_dqd", "Phi", "Phi_t", "gamma", "s", "events",
           "power", "b", "tau_id", "gravity", "bias", "contact_gap", "contact_rate", "contact_bias",
           "contact_slips", "nh_b",
           "nh_gamma"}


def _vector(exprs):
    return sp.Matrix(list(exprs)) if len(exprs) else sp.zeros(0, 1)


class Reference:
    """Lazily built, lambdified reference quantities of one DrawnModel.

    ``value(name, state)``: the quantity ``name`` (see _build) at a State (q, qd, t, params by
    name, w, lam, we) as a float array (vectors 1-D)."""

    def __init__(self, drawn):
        self.drawn = drawn
        self.q = sp.Matrix(drawn.coords)
        self.qd = sp.Matrix([c.d for c in drawn.coords])
        n, m, ne = len(drawn.coords), len(drawn.constraints), len(drawn.elements)
        self.n, self.m, self.ne, self.nc = n, m, ne, len(drawn.contacts)
        self.nr = nr = len(drawn.nonholonomic)
        self.params = list(drawn.params)
        self.w = sp.Matrix(sp.symbols(f"ref_w0:{n}", real=True))
        self.lam = _vector(sp.symbols(f"ref_lam0:{m}", real=True)) if m else sp.zeros(0, 1)
        self.we = _vector(sp.symbols(f"ref_we0:{ne}", real=True)) if ne else sp.zeros(0, 1)
        self.mu = _vector(sp.symbols(f"ref_mu0:{nr}", real=True)) if nr else sp.zeros(0, 1)
        self.args = [*self.q, *self.qd, t, *self.params, *self.w, *self.lam, *self.we, *self.mu]
        self._exprs, self._functions = {}, {}

    # -- symbolic quantities ------------------------------------------------------------------
    def expr(self, name):
        if name not in self._exprs:
            self._exprs[name] = getattr(self, f"_{name}")()
        return self._exprs[name]

    def _generalized_forces(self):
        """Q (n, 1) from the given forces or by virtual work of the point forces."""
        Q = sp.zeros(self.n, 1)
        if self.drawn.forces:
            Q += _vector(self.drawn.forces)
        for point, force in self.drawn.point_forces:
            Q += sp.Matrix(point).jacobian(self.q).T * sp.Matrix(force)
        return Q

    def _H(self):
        return sp.hessian(self.drawn.T, self.qd)

    def _dT_dqd(self):
        return sp.Matrix([self.drawn.T]).jacobian(self.qd).T

    def _forces(self):
        """Q - dD/dqd - dV/dq + dT/dq (n, 1): everything in the equations but d/dt dT/dqd."""
        d = self.drawn
        grad = lambda f, x: sp.Matrix([f]).jacobian(x).T   # noqa: E731
        return self._generalized_forces() - grad(d.dissipation, self.qd) - grad(d.V, self.q) + grad(d.T, self.q)

    def _rhs(self):
        return self.expr("forces") - self.expr("dT_dqd").jacobian(self.q) * self.qd

    def _momentum_rate(self):
        return self.expr("forces")

    def _E(self):
        return self.drawn.T + self.drawn.V

    def _drhs_dq(self):
        return self.expr("rhs").jacobian(self.q)

    def _drhs_dqd(self):
        return self.expr("rhs").jacobian(self.qd)

    def _dmom_dq(self):
        return self.expr("momentum_rate").jacobian(self.q)

    def _dmom_dqd(self):
        return self.expr("momentum_rate").jacobian(self.qd)

    def _dHw_dq(self):
        return (self.expr("H") * self.w).jacobian(self.q)

    def _tau_id(self):
        """inverse dynamics at qdd = w: H w - rhs."""
        return self.expr("H") * self.w - self.expr("rhs")

    def _gravity(self):
        return sp.Matrix([self.drawn.V]).jacobian(self.q).T

    def _bias(self):
        return -self.expr("rhs")

    def _events(self):
        return _vector(self.drawn.events) if self.drawn.events else sp.zeros(0, 1)

    def _Phi(self):
        return _vector(self.drawn.constraints)

    def _power(self):
        """(P, dP/dq, dP/dqd, dP/dt) with P = qd . (Q - dD/dqd) - d(T - V)/dt = dE/dt."""
        d = self.drawn
        Q = self._generalized_forces() - sp.Matrix([d.dissipation]).jacobian(self.qd).T
        P = (self.qd.T * Q)[0, 0] - sp.diff(d.T - d.V, t)
        return sp.Matrix([P, *(sp.diff(P, x) for x in [*self.q, *self.qd, t])])

    def _b(self):
        """dT/dqd at qd = 0 (the T1 = b . qd part of T)."""
        return self.expr("dT_dqd").subs({v: 0 for v in self.qd})

    def _db(self):
        return self.expr("b").jacobian(self.q)

    def _Phi_t(self):
        return self.expr("Phi").diff(t)

    def _J(self):
        return self.expr("Phi").jacobian(self.q)

    def _gamma(self):
        """gamma = -(dJ/dt) qd, so that J qdd = gamma on the constraint manifold."""
        return -(self.expr("J") * self.qd).jacobian(self.q) * self.qd

    def _dJw_dq(self):
        return (self.expr("J") * self.w).jacobian(self.q)

    def _dJTlam_dq(self):
        return (self.expr("J").T * self.lam).jacobian(self.q)

    def _s(self):
        return _vector([e[1] for e in self.drawn.elements])

    def _G(self):
        return self.expr("s").jacobian(self.q)

    def _coef(self):
        """Rows (stiffness, threshold, 0) for Saint-Venant (threshold = yield force / stiffness
        when given so), (bound, 0, 1) for dry friction."""
        rows = []
        for kind, _, coef, threshold, yield_force in self.drawn.elements:
            if kind == "dry_friction":
                rows.append([coef, 0, _ELEMENT_KIND[kind]])
            else:
                rows.append([coef, threshold if threshold is not None else yield_force / coef, _ELEMENT_KIND[kind]])
        return sp.Matrix(rows) if rows else sp.zeros(0, 3)

    def _hess_w(self):
        out = sp.zeros(self.n, self.n)
        for e in range(self.ne):
            out += self.we[e] * sp.hessian(self.expr("s")[e], self.q)
        return out

    def _contact_gap(self):
        return _vector([gap for gap, _, _, _ in self.drawn.contacts])

    def _contact_WN(self):
        return self.expr("contact_gap").jacobian(self.q)

    def _contact_slips(self):
        """The slip velocities (2c,): every contact's first, then every contact's second (0
        where a contact has fewer)."""
        pairs = []
        for _, _, _, slip in self.drawn.contacts:
            slips = () if slip is None else (slip if isinstance(slip, tuple) else (slip,))
            pairs.append(tuple(slips) + (0,) * (2 - len(slips)))
        return _vector([p[0] for p in pairs] + [p[1] for p in pairs])

    def _contact_WT(self):
        """Rows d slip/d qd (2c, n): tangent 1 of each contact, then tangent 2 (zero rows where
        a contact has no such slip velocity)."""
        return self.expr("contact_slips").jacobian(self.qd)

    def _contact_bias(self):
        """(dg/dt, the slips at qd = 0) (3c,): local velocities are W qd + these."""
        slips = self.expr("contact_slips").subs({v: 0 for v in self.qd})
        return self.expr("contact_gap").diff(t).col_join(slips)

    def _contact_rate(self):
        """d(W qd + bias)/dq qd + d(W qd + bias)/dt (3c,) with W = [W_N; W_T]."""
        local = (self.expr("contact_WN").col_join(self.expr("contact_WT")) * self.qd
                 + self.expr("contact_bias"))
        return local.jacobian(self.q) * self.qd + local.diff(t)

    def _contact_coef(self):
        rows = [[restitution, friction] for _, restitution, friction, _ in self.drawn.contacts]
        return sp.Matrix(rows) if rows else sp.zeros(0, 2)

    def _nh_c(self):
        return _vector(self.drawn.nonholonomic)

    def _nh_A(self):
        return self.expr("nh_c").jacobian(self.qd) if self.nr else sp.zeros(0, self.n)

    def _nh_b(self):
        return self.expr("nh_c").subs({v: 0 for v in self.qd})

    def _nh_gamma(self):
        c = self.expr("nh_c")
        return -(c.jacobian(self.q) * self.qd + c.diff(t)) if self.nr else sp.zeros(0, 1)

    def _nh_dAw(self):
        return (self.expr("nh_A") * self.w).jacobian(self.q) if self.nr else sp.zeros(0, self.n)

    def _nh_dATmu(self):
        return (self.expr("nh_A").T * self.mu).jacobian(self.q) if self.nr else sp.zeros(self.n, self.n)

    def _nh_dc(self):
        return self.expr("nh_c").jacobian(self.q) if self.nr else sp.zeros(0, self.n)

    def _nh_dgamma_dq(self):
        return self.expr("nh_gamma").jacobian(self.q) if self.nr else sp.zeros(0, self.n)

    def _nh_dgamma_dqd(self):
        return self.expr("nh_gamma").jacobian(self.qd) if self.nr else sp.zeros(0, self.n)

    def _gamma_dq(self):
        return self.expr("gamma").jacobian(self.q) if self.m else sp.zeros(0, self.n)

    def _gamma_dqd(self):
        return self.expr("gamma").jacobian(self.qd) if self.m else sp.zeros(0, self.n)

    # -- numbers --------------------------------------------------------------------------------
    def value(self, name, state):
        """The quantity at a state: float, or array (column vectors flattened)."""
        if name not in self._functions:
            self._functions[name] = sp.lambdify(self.args, _jumps_settled(self.expr(name)),
                                                modules=_MODULES)
        expr = self.expr(name)
        p = [state.params[s.name] for s in self.params]
        mu = state.mu if state.mu is not None else np.zeros(self.nr)
        values = [*state.q, *state.qd, state.t, *p, *state.w, *state.lam, *state.we, *mu]
        out = np.asarray(self._functions[name](*values), dtype=float)
        if isinstance(expr, sp.MatrixBase):
            out = out.reshape(expr.shape)
            return out[:, 0] if name in VECTORS else out
        return float(out)

    def accelerations(self, state):
        """qdd (n,) solving H qdd = rhs numerically (numpy)."""
        return np.linalg.solve(self.value("H", state), self.value("rhs", state))
