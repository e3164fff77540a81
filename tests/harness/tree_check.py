"""Checks of a module generated from a drawn spatial tree (trees.py).

check_against_reference: every kernel the module has (its KERNELS, forward_dynamics,
forward_dynamics_torques, accelerations) against TreeReference at each state, as
check.check_kernels does for the expression models; forward_dynamics_jacobian against central
differences of the reference's accelerations; the Jacobian kernels against central differences
of the kernels they differentiate (fd.py).

check_invariants: what holds for any tree, without a reference (for trees too large for it):
H symmetric positive definite; E - qd.H qd/2 independent of qd and its gradient the gravity
forces; dE/dt = qd . tau along the motion under joint torques tau (central differences of the
energy kernel); inverse_dynamics(forward_dynamics_torques(tau)) = tau; bias forces at qd = 0 are
the gravity forces; momentum_rate - rhs = d(H qd)/dq qd; and the finite-difference checks of
the Jacobian kernels.

Every comparison is counted in check.CHECKED (kind, mode) like the rest of the harness, kinds
prefixed "tree:" for the invariants.
"""

from __future__ import annotations

import numpy as np

from .check import CHECKED, RTOL, State, call_kernel, check_kernels, compare
from .fd import FD_RTOL, check_derivatives, derivative
from .trees import sample_states


def tree_states(drawn, mod, ref_params, seed, count):
    """``count`` harness States for a tree module (t = 0: nothing depends on time)."""
    rng = np.random.default_rng(seed)
    out = []
    for q, qd, values in sample_states(drawn, ref_params, rng, count):
        p = np.array([values[name] for name in mod.PARAMS], dtype=float)
        n = len(q)
        out.append(State(q, qd, 0.0, values, p, rng.uniform(-1, 1, n), np.zeros(0), np.zeros(0)))
    return out


#: Jacobian kernel -> (the kernel it differentiates, its output, the reference quantity)
JACOBIANS = {"rhs_jacobian": ("rhs", ("drhs_dq", "drhs_dqd")),
             "momentum_rate_jacobian": ("momentum_rate", ("dmom_dq", "dmom_dqd")),
             "mass_matvec_dq": ("H", ("dHw_dq",))}


def check_against_reference(mod, kern, ref, state, mode):
    """Mismatches of every kernel of ``mod`` (run as ``kern``) against TreeReference ``ref``:
    the Jacobian kernels against central differences of the reference (its quantities are exact
    only to first order in q), the energy up to a constant (below), the others exactly."""
    failures = check_kernels(mod, kern, ref, state, mode, skip=(*JACOBIANS, "energy"))
    failures += _energy_vs_reference(kern, ref, state, mode)
    for name in set(JACOBIANS) & set(mod.KERNELS):
        failures += _jacobian_vs_reference(kern, name, ref, state, mode)
    if hasattr(mod, "forward_dynamics_jacobian"):
        failures += _forward_jacobian_vs_reference(kern, ref, state, mode)
    try:
        failures += check_derivatives(mod, kern, state, (ref.n, 0, 0), mode)
    except Exception as exc:       # noqa: BLE001  a kernel raising near the state
        failures.append(f"finite differences: raised {type(exc).__name__}: {exc}")
    return [f for f in failures if f]


def _energy_vs_reference(kern, ref, state, mode):
    """E(q, qd) - E(0, 0) against the reference's: a potential is defined up to a constant, and
    lg.gravity_potential measures heights from the nearest fixed point, which is not the
    reference's O when the user set a zero velocity on another point (J0.v2pt_theory(O, N, N))."""
    n = ref.n
    rest = State(**{**vars(state), "q": np.zeros(n), "qd": np.zeros(n)})
    got = kern.energy(state.q, state.qd, state.t, state.p) - kern.energy(rest.q, rest.qd, rest.t, rest.p)
    CHECKED[("energy", mode)] += 1
    return [compare("energy.E - E(0, 0)", got, ref.value("E", state) - ref.value("E", rest))]


def _jacobian_vs_reference(kern, name, ref, state, mode):
    """A Jacobian kernel's outputs against central differences of the reference quantity."""
    base, outputs = JACOBIANS[name]
    n = ref.n
    values = call_kernel(kern, name, state, (n, 0, 0))
    at = lambda **c: State(**{**vars(state), **c})                                    # noqa: E731
    if name == "mass_matvec_dq":
        expected = [derivative(lambda q: ref.value("H", at(q=q)) @ state.w, state.q)]
    else:
        expected = [derivative(lambda q: ref.value(base, at(q=q)), state.q),
                    derivative(lambda v: ref.value(base, at(qd=v)), state.qd)]
    CHECKED[(name, mode)] += 1
    return [compare(f"{name}.{key}", values[key], e, FD_RTOL, FD_RTOL) for key, e in zip(outputs, expected)]


def _reference_qdd(ref, state, q=None, qd=None):
    s = State(**{**vars(state), "q": state.q if q is None else q, "qd": state.qd if qd is None else qd})
    return np.linalg.solve(ref.value("H", s), ref.value("rhs", s))


def _forward_jacobian(kern, state):
    n = len(state.q)
    H, W, Jq, Jqd = (np.full((n, n), np.nan) for _ in range(4))
    qdd = np.full(n, np.nan)
    status = kern.forward_dynamics_jacobian(state.q, state.qd, state.t, state.p, H, qdd, Jq, Jqd, W)
    return status, qdd, Jq, Jqd


def _forward_jacobian_vs_reference(kern, ref, state, mode):
    status, qdd, Jq, Jqd = _forward_jacobian(kern, state)
    CHECKED[("forward_dynamics_jacobian", mode)] += 1
    return [None if status == 0 else f"forward_dynamics_jacobian: status {status}",
            compare("forward_dynamics_jacobian.qdd", qdd, _reference_qdd(ref, state)),
            compare("forward_dynamics_jacobian.Jq", Jq,
                    derivative(lambda q: _reference_qdd(ref, state, q=q), state.q), FD_RTOL, FD_RTOL),
            compare("forward_dynamics_jacobian.Jqd", Jqd,
                    derivative(lambda v: _reference_qdd(ref, state, qd=v), state.qd), FD_RTOL, FD_RTOL)]


# ------------------------------------------------------------------------------------ invariants


def _call(kern, name, *args, shape):
    out = np.full(shape, np.nan)
    getattr(kern, name)(*args, out)
    return out


def check_invariants(mod, kern, state, mode):
    """Mismatches of the invariants (module docstring) at one state."""
    q, qd, t, p, tau = state.q, state.qd, state.t, state.p, state.w
    n = len(q)
    failures = []

    def counted(kind, failure):
        CHECKED[(f"tree:{kind}", mode)] += 1
        failures.append(failure)

    H = _call(kern, "mass_matrix", q, t, p, shape=(n, n))
    eig = np.linalg.eigvalsh((H + H.T) / 2)
    counted("H symmetric positive definite",
            compare("H symmetric", H, H.T) or (None if eig.min() > 1e-12 * max(1.0, eig.max())
                                               else f"H not positive definite: eigenvalues {eig.tolist()}"))

    energy = lambda x, v: kern.energy(x, v, t, p)                                    # noqa: E731
    E, E_rest = energy(q, qd), energy(q, np.zeros(n))
    counted("E = qd.H qd/2 + V(q)", compare("energy - qd.H qd/2", E - qd @ H @ qd / 2, E_rest))
    gravity = _call(kern, "gravity_forces", q, t, p, shape=n)
    counted("gravity = dV/dq", compare("gravity_forces vs d E(q, 0)/dq", gravity,
                                       derivative(lambda x: np.array([energy(x, np.zeros(n))]), q)[0],
                                       FD_RTOL, FD_RTOL))

    qdd = np.full(n, np.nan)
    status = kern.forward_dynamics_torques(q, qd, tau, t, p, np.full((n, n), np.nan), qdd)
    along = derivative(lambda s: np.array([energy(q + s[0] * qd, qd + s[0] * qdd)]), np.zeros(1))[0, 0]
    counted("dE/dt = qd.tau", None if status == 0 else f"forward_dynamics_torques: status {status}")
    counted("dE/dt = qd.tau", compare("dE/dt", along, qd @ tau, FD_RTOL, FD_RTOL))
    counted("inverse(forward) = tau", compare("inverse_dynamics(forward_dynamics_torques(tau))",
                                              _call(kern, "inverse_dynamics", q, qd, qdd, t, p, shape=n), tau))
    counted("bias at rest = gravity", compare("bias_forces(q, 0)",
                                              _call(kern, "bias_forces", q, np.zeros(n), t, p, shape=n), gravity))

    rhs = np.full(n, np.nan)
    kern.dynamics(q, qd, t, p, np.full((n, n), np.nan), rhs)
    mom = _call(kern, "momentum_rate", q, qd, t, p, shape=n)
    dHqd = derivative(lambda x: _call(kern, "mass_matrix", x, t, p, shape=(n, n)) @ qd, q) @ qd
    counted("momentum_rate - rhs = d(H qd)/dq qd", compare("momentum_rate - rhs", mom - rhs, dHqd, FD_RTOL, FD_RTOL))

    if hasattr(mod, "forward_dynamics_jacobian"):
        def accelerations(x, v):
            out = np.full(n, np.nan)
            kern.forward_dynamics(x, v, t, p, np.full((n, n), np.nan), out)
            return out
        status, qdd0, Jq, Jqd = _forward_jacobian(kern, state)
        CHECKED[("fd:forward_dynamics_jacobian", mode)] += 1
        failures += [None if status == 0 else f"forward_dynamics_jacobian: status {status}",
                     compare("forward_dynamics_jacobian.qdd", qdd0, accelerations(q, qd), RTOL, RTOL),
                     compare("fd:forward_dynamics_jacobian.Jq", Jq, derivative(lambda x: accelerations(x, qd), q),
                             FD_RTOL, FD_RTOL),
                     compare("fd:forward_dynamics_jacobian.Jqd", Jqd, derivative(lambda v: accelerations(q, v), qd),
                             FD_RTOL, FD_RTOL)]
    try:
        failures += check_derivatives(mod, kern, state, (n, 0, 0), mode)
    except Exception as exc:       # noqa: BLE001
        failures.append(f"finite differences: raised {type(exc).__name__}: {exc}")
    return [f for f in failures if f]
