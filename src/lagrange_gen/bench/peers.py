"""The peers a user would pick instead of our steppers, measured in the same run:

* scipy solve_ivp DOP853 and Radau (with the exact generated Jacobian) on our generated
  right-hand side (bench.reference.ode_rhs, or the index-1 KKT form of a constrained model);
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


def solver_run(f, y0, t_end, t_grid, method, rtol, jac=None, repeats=1):
    """One solve_ivp run at rtol (atol = rtol * 1e-3, absolute errors are in O(1) units):
    returns (best wall seconds over repeats, y_grid (2n, S) or None, y_end (2n,) or None, nfev,
    message). A failed solve (success False or an exception) returns None states and the
    message, with the time to failure."""
    from .steppers import _best_of
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
    best, sol = _best_of(go, max(1, repeats))
    return best, sol.y, sol.y[:, -1], sol.nfev, ""


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

    from ..model_file import load_model
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
    """rhs(t, y) of the sympy.mechanics peer, parameters p (in param_names order), and the
    seconds spent deriving and lambdifying (reported, not part of the timed runs)."""
    import sympy as sp
    start = time.perf_counter()
    M, F, qs, params = mechanics_equations(model_file)
    (M, F), states = _plain_symbols([M, F], qs)
    by_name = {s.name: s for s in params}
    psyms = [by_name[name] for name in param_names]
    fM = sp.lambdify([states, psyms], M, "numpy")
    fF = sp.lambdify([states, psyms], F, "numpy")
    setup = time.perf_counter() - start
    pv = list(p)

    def f(t, y):
        return np.linalg.solve(np.asarray(fM(y, pv), dtype=float),
                               np.asarray(fF(y, pv), dtype=float).ravel())
    return f, setup


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
    M, F, qs, params = mechanics_equations(model_file)
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
