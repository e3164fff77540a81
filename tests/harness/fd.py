"""Central finite differences of the kernels against the Jacobian kernels that differentiate them.

This check needs no reference at all: a Jacobian kernel must be the derivative of the kernel it
differentiates, both as generated. Each check is recorded as ``fd:<jacobian kernel>``.
"""

from __future__ import annotations

import numpy as np

from .check import CHECKED, call_kernel, compare

FD_STEP = 1e-6       # relative step of the central differences
FD_RTOL = 1e-6       # truncation ~ step**2 f''' and rounding ~ 1e-16 |f| / step stay far below


def derivative(f, x):
    """Central differences d f / d x (f(x).shape + (len(x),)), step FD_STEP * max(1, |x_i|)."""
    columns = []
    for i in range(len(x)):
        h = FD_STEP * max(1.0, abs(x[i]))
        e = np.zeros_like(x)
        e[i] = h
        columns.append((np.asarray(f(x + e)) - np.asarray(f(x - e))) / (2 * h))
    return np.stack(columns, axis=-1)


def _with(state, **changes):
    return type(state)(**{**vars(state), **changes})


def _compare(name, label, exact, fd, mode):
    CHECKED[(f"fd:{name}", mode)] += 1
    return compare(f"fd:{name}.{label}", exact, fd, rtol=FD_RTOL, floor=FD_RTOL)


def check_derivatives(mod, kern, state, sizes, mode):
    """Every Jacobian kernel of the module at one state against central differences of the
    kernel it differentiates: a list of mismatches."""
    names = set(mod.KERNELS)
    n, m, ne = sizes[:3]
    value = lambda name, quantity, st: call_kernel(kern, name, st, sizes)[quantity]   # noqa: E731
    at_q = lambda q: _with(state, q=q)                                                 # noqa: E731
    out = []
    for name, base, quantity in (("rhs_jacobian", "dynamics", "rhs"),
                                 ("momentum_rate_jacobian", "momentum_rate", "momentum_rate")):
        if name in names:
            jac = call_kernel(kern, name, state, sizes)
            dq = derivative(lambda q: value(base, quantity, at_q(q)), state.q)
            dqd = derivative(lambda v: value(base, quantity, _with(state, qd=v)), state.qd)
            keys = ("drhs_dq", "drhs_dqd") if name == "rhs_jacobian" else ("dmom_dq", "dmom_dqd")
            out += [_compare(name, "Jq", jac[keys[0]], dq, mode), _compare(name, "Jqd", jac[keys[1]], dqd, mode)]
    if "mass_matvec_dq" in names:
        fd = derivative(lambda q: value("mass_matrix", "H", at_q(q)) @ state.w, state.q)
        out.append(_compare("mass_matvec_dq", "out_mat", value("mass_matvec_dq", "dHw_dq", state), fd, mode))
    if "constraints" in names and m:
        out += _constraints(kern, state, sizes, mode, names)
    if "elements" in names and ne:
        G = value("elements", "G", state)
        out.append(_compare("elements", "G", G, derivative(lambda q: value("elements", "s", at_q(q)), state.q), mode))
        if "elements_hessian" in names:
            fd = derivative(lambda q: value("elements", "G", at_q(q)).T @ state.we, state.q)
            out.append(_compare("elements_hessian", "out_mat", value("elements_hessian", "hess_w", state), fd, mode))
    if "contacts" in names:
        WN = value("contacts", "contact_WN", state)
        fd = derivative(lambda q: value("contacts", "contact_gap", at_q(q)), state.q)
        out.append(_compare("contacts", "WN", WN, fd, mode))
        if "contact_bias" in names:         # its normal rows are dg/dt
            gap_dt = derivative(lambda s: value("contacts", "contact_gap",
                                                _with(state, t=state.t + s[0])), np.zeros(1))[:, 0]
            out.append(_compare("contact_bias", "out", value("contact_bias", "contact_bias",
                                                             state)[:len(gap_dt)], gap_dt, mode))
        if "contact_rates" in names:        # d/ds [W(q + s qd, t + s) qd + b(q + s qd, t + s)]
            def local_at(s):
                moved = _with(state, q=state.q + s[0] * state.qd, t=state.t + s[0])
                W = np.vstack((value("contacts", "contact_WN", moved),
                               value("contacts", "contact_WT", moved)))
                return W @ state.qd + value("contact_bias", "contact_bias", moved)
            along = derivative(local_at, np.zeros(1))[:, 0]
            out.append(_compare("contact_rates", "out", value("contact_rates", "contact_rate",
                                                               state), along, mode))
    return [f for f in out if f]


def _constraints(kern, state, sizes, mode, names):
    """J = dPhi/dq, gamma = -(d/ds J(q + s qd) qd) at s = 0, d(J w)/dq and d(J^T lam)/dq."""
    values = call_kernel(kern, "constraints", state, sizes)
    J_at = lambda q: call_kernel(kern, "constraints", _with(state, q=q), sizes)["J"]        # noqa: E731
    phi_at = lambda q: call_kernel(kern, "constraints", _with(state, q=q), sizes)["Phi"]    # noqa: E731
    along = derivative(lambda s: J_at(state.q + s[0] * state.qd) @ state.qd, np.zeros(1))[:, 0]
    out = [_compare("constraints", "J", values["J"], derivative(phi_at, state.q), mode),
           _compare("constraints", "gamma", values["gamma"], -along, mode)]
    if "constraint_dq" in names:
        exact = call_kernel(kern, "constraint_dq", state, sizes)
        out.append(_compare("constraint_dq", "dJw", exact["dJw_dq"], derivative(lambda q: J_at(q) @ state.w, state.q), mode))
        out.append(_compare("constraint_dq", "dJTlam", exact["dJTlam_dq"],
                            derivative(lambda q: J_at(q).T @ state.lam, state.q), mode))
    return out
