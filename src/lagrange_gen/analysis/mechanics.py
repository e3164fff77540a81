"""The equations of a model derived a second, independent way: sympy.physics.mechanics'
LagrangesMethod on the model's own L = T - V (conservative, unconstrained models only). The
precision suite times it as a peer (what PyDy's default "lambdify" generator does); the tests
compare it with the generated right-hand side.
"""

from __future__ import annotations

import numpy as np


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
