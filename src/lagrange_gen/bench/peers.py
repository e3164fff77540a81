"""The peers a user would pick instead of our steppers, measured in the same run:

* scipy solve_ivp DOP853 and Radau (with the exact generated Jacobian) on our generated
  right-hand side (analysis.reference.ode_rhs, or the index-1 KKT form of a constrained model);
* sympy.physics.mechanics: LagrangesMethod on the model's own L = T - V, its mass_matrix_full and
  forcing_full lambdified to numpy, y' = M^-1 F per call, integrated by DOP853 (what PyDy's
  default "lambdify" generator does);
* PyDy's generate_ode_function on the same equations with its fastest available generator,
  when pydy is installed (optional).

Each peer is a function rhs(t, y) [+ jac]; ``sweep`` runs one solver over tolerances.
"""

from __future__ import annotations

import time

import numpy as np
from scipy.integrate import solve_ivp

from ..analysis import reference


def solver_run(f, y0, t_end, t_grid, method, rtol, jac=None, repeats=1):
    """One solve_ivp run at rtol (atol = rtol * 1e-3, absolute errors are in O(1) units):
    returns (best wall seconds over repeats, y_grid (2n, S) or None, y_end (2n,) or None, nfev,
    message). A failed solve (success False or an exception) returns None states and the
    message, with the time to failure."""
    from .steppers import best_of
    kwargs = {"jac": jac} if jac is not None else {}

    def go():
        return solve_ivp(f, (0.0, t_end), y0, method=method, rtol=rtol, atol=rtol * 1e-3,
                         t_eval=t_grid, **kwargs)
    start = time.perf_counter()
    try:
        sol = go()
    except (FloatingPointError, np.linalg.LinAlgError, ValueError) as exc:
        return time.perf_counter() - start, None, None, 0, str(exc)
    if not sol.success:
        return time.perf_counter() - start, None, None, sol.nfev, sol.message
    best, sol = best_of(go, max(1, repeats))
    return best, sol.y, sol.y[:, -1], sol.nfev, ""


def mechanics_rhs(model_file, param_names, p):
    """rhs(t, y) of the sympy.mechanics peer (analysis.reference), parameters p (in param_names
    order), and the seconds spent deriving and lambdifying (reported, not part of the timed
    runs)."""
    start = time.perf_counter()
    f = reference.mechanics_rhs(model_file, param_names, p)
    return f, time.perf_counter() - start


def pydy_rhs(model_file, param_names, p):
    """rhs(t, y) from PyDy's generate_ode_function on the same LagrangesMethod equations, with
    speeds u = q' (M u' = F, q' = u), cython when it compiles, else lambdify. Returns
    (f, setup seconds, generator name) or None when pydy is not installed."""
    try:
        from pydy.codegen.ode_function_generators import generate_ode_function
    except ImportError:
        return None
    from sympy.physics import mechanics as me
    start = time.perf_counter()
    M, F, qs, params = reference.mechanics_equations(model_file)
    n = len(qs)
    us = list(me.dynamicsymbols(" ".join(f"u{i}" for i in range(n)))) if n > 1 else \
        [me.dynamicsymbols("u0")]
    rep = {q.diff(): u for q, u in zip(qs, us)}
    Mu = M[n:, n:].xreplace(rep)
    Fu = F[n:, :].xreplace(rep)
    by_name = {s.name: s for s in params}
    psyms = [by_name[name] for name in param_names]
    import sympy as sp
    rhs, errors = None, []
    for generator in ("cython", "lambdify"):
        try:
            rhs = generate_ode_function(Fu, qs, us, psyms, mass_matrix=Mu,
                                        coordinate_derivatives=sp.Matrix(us),
                                        generator=generator)
            break
        except Exception as exc:    # noqa: BLE001  (cython missing or failing: next one)
            errors.append(f"{generator}: {exc}")
    if rhs is None:
        raise RuntimeError("PyDy could not generate a right-hand side: " + "; ".join(errors))
    pv = np.asarray(p, dtype=float)

    def f(t, y):
        # PyDy returns one reused output buffer; solve_ivp keeps the previous f(t, y) and would
        # see it overwritten (4x more evaluations, wrong steps), so copy as a user must.
        return rhs(y, t, pv).copy()
    return f, time.perf_counter() - start, generator
