"""Turn a stepper's status code into the exception that names the step, time, state and residual.

The run loop (steppers/core/run_loop.py) stops on a status and leaves in ``last`` the state the failing
step started from (Newton failure, singular matrix) or the offending state after it (NON_FINITE,
UNSTABLE), with steps_done = -1 when the initial state itself was refused. Non-finite values
anywhere (state, energy, Newton matrix or residual: a division by zero or log of 0 in the model)
become BlowUp, so that "singular" and "did not converge" are only said when they are true.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import BlowUp, NewtonDivergence, SimulationError, SingularMass, SingularNewtonMatrix
from ..steppers.core import status as st
from ..steppers.core import registry
from ..steppers.core.layout import read_last

_DOMAIN = "(division by zero, or log/sqrt outside its domain, in the model's expressions?)"


def format_state(coords, q, v):
    """'x=0.1, theta=0.5, x_dot=0, theta_dot=0.2'."""
    parts = [f"{c}={x:.6g}" for c, x in zip(coords, q)]
    parts += [f"{c}_dot={x:.6g}" for c, x in zip(coords, v)]
    return ", ".join(parts)


def raise_for_status(code, module, method, step, n_steps, last, max_iter, h, p):
    """Raise the exception of status ``code``; step is 1-based, 0 for the initial state;
    n_steps None for an adaptive run (its step count is not known in advance)."""
    n = module.N_COORDS
    t, q, v, _, resid = read_last(last, n)[:5]
    state = format_state(module.COORDS, q, v)
    at = "the initial state" if step == 0 else f"step {step}" + (f" of {n_steps}" if n_steps else "")
    where = f"{module.NAME}, {method}: {at} (t = {t:.9g}, h = {h:g})"
    kwargs = dict(step=step, time=float(t), state=np.concatenate([q, v]), residual=float(resid))
    if code == st.NEWTON_DIVERGED and math.isfinite(resid):
        raise NewtonDivergence(f"{where}: Newton did not converge in {max_iter} iterations "
                               f"(residual {resid:.3g}) from {state}; reduce h or raise max_iter",
                               **kwargs)
    if code in (st.NEWTON_DIVERGED, st.NON_FINITE):
        raise BlowUp(f"{where}: {_non_finite(module, q, v, t, p, resid)}", **kwargs)
    if code == st.SINGULAR_MASS:
        what = "H(q) or J H^-1 J^T" if registry.spec(method).constraints else "H(q)"
        raise SingularMass(f"{where}: singular mass matrix {what} at {state}"
                           f"{_constraint_hint(module, method, q, p)}", **kwargs)
    if code == st.SINGULAR_NEWTON:
        system = "the Jacobian of the step's equations"
        if registry.spec(method).constraints:
            system = "the KKT matrix of the step's equations and constraints"
        raise SingularNewtonMatrix(
            f"{where}: singular Newton matrix ({system}; H(q) is not what failed) in the step "
            f"from {state}{_constraint_hint(module, method, q, p)}; reduce h", **kwargs)
    if code == st.STEP_TOO_SMALL:
        raise BlowUp(f"{where}: the step size fell below the time resolution at {state} (the "
                     f"solution blows up in finite time, or a singularity?)", **kwargs)
    if code == st.TOO_MANY_STEPS:
        raise SimulationError(f"{where}: max_steps step attempts without reaching the end, at "
                              f"{state}; raise max_steps or loosen rtol/atol", **kwargs)
    if code == st.CONTACT_NOT_CONVERGED:
        raise SimulationError(f"{where}: the contact problem did not converge (projected "
                              f"Gauss-Seidel's last sweep changed the impulses by {resid:.3g}, "
                              f"and Lemke's method cycled) from {state}; raise max_sweeps or "
                              f"contact_tol, or reduce h", **kwargs)
    if code == st.CONTACT_NO_SOLUTION:
        raise SimulationError(f"{where}: the contact problem has no solution (Lemke's method "
                              f"ends on a ray: no impulses or forces meet the contact laws, as "
                              f"in Painleve's paradox of sliding friction) at {state}; lower the "
                              f"friction, or model the contact as compliant", **kwargs)
    if code == st.UNSTABLE:
        raise BlowUp(f"{where}: the state grew past the blow-up bound (unstable at this h?): "
                     f"{state}", **kwargs)
    raise SimulationError(f"{where}: stepper returned unknown status {code}", **kwargs)


def _non_finite(module, q, v, t, p, resid):
    """Which value was not finite: the state, its energy, or one inside the step."""
    state = format_state(module.COORDS, q, v)
    if not (np.all(np.isfinite(q)) and np.all(np.isfinite(v))):
        return f"the state became non-finite: {state}"
    energy = module.energy(np.ascontiguousarray(q), np.ascontiguousarray(v), float(t), p)
    if not math.isfinite(energy):
        big = max(np.abs(q).max(initial=0.0), np.abs(v).max(initial=0.0)) > 1e100
        why = "(the state is so large that E overflows: unstable at this h?)" if big else _DOMAIN
        return f"the energy became non-finite (E = {energy}) at {state} {why}"
    return (f"a non-finite value (residual {resid:.3g}) inside the step from {state} {_DOMAIN}; "
            f"if the model is regular there, the step diverged: reduce h")


def _constraint_hint(module, method, q, p):
    if not registry.spec(method).constraints:
        return ""
    from .consistent import diagnose_singular
    return diagnose_singular(module, np.ascontiguousarray(q), p)
