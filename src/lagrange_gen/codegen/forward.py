"""Forward dynamics and the Python convenience `accelerations` of a generated module.

Two variants, chosen from the model:

* H(q) depends on q: every call fills H and factors it (Cholesky, in numba).
* H is constant: it is factored once, at import, for the default values of the parameters it
  depends on (MASS_FACTOR, lower Cholesky factor L with H = L L^T); a call evaluates only
  rhs = Q - h - g and does two triangular solves, unless the caller passes other values for
  those parameters, in which case H is formed and factored as in the general case.
"""

from __future__ import annotations

_GENERAL = '''@njit(cache=True, _nrt=False)
def forward_dynamics(q, qd, t, p, H, qdd):
    """Solve H(q) qdd = rhs by Cholesky; H (n, n) is workspace, qdd (n,) the output.
    Returns OK, or SINGULAR_MASS when H is not numerically positive definite."""
    dynamics(q, qd, t, p, H, qdd)
    if not cholesky_inplace(H):
        return SINGULAR_MASS
    cholesky_solve_inplace(H, qdd)
    return OK
'''

_CONSTANT = '''def _factor_mass_matrix(p):
    """Lower Cholesky factor (n, n) of the constant H at parameters p (ValueError if not SPD)."""
    L = np.empty((N_COORDS, N_COORDS))
    mass_matrix(np.zeros(N_COORDS), p, L)
    if not cholesky_inplace(L):
        raise ValueError(f"{{NAME}}: the constant mass matrix is not positive definite at the defaults")
    return np.tril(L)          # the upper triangle still held H


# H does not depend on q: factored once, here, for the defaults of the parameters it uses
# ({used}). numba freezes this array into forward_dynamics as a constant.
MASS_FACTOR = _factor_mass_matrix(DEFAULT_PARAMS)


@njit(cache=True, _nrt=False)
def forward_dynamics(q, qd, t, p, H, qdd):
    """Solve H qdd = rhs with the constant H: by MASS_FACTOR (no factorization) when the
    parameters H depends on have their default values, else by factoring H into the workspace
    H (n, n). qdd (n,) is the output. Returns OK, or SINGULAR_MASS."""
    rhs(q, qd, t, p, qdd)
    if {test}:
        cholesky_solve_inplace(MASS_FACTOR, qdd)
        return OK
    mass_matrix(q, p, H)
    if not cholesky_inplace(H):
        return SINGULAR_MASS
    cholesky_solve_inplace(H, qdd)
    return OK
'''

_ACCELERATIONS = '''

def accelerations(q, qd, t=0.0, params=None):
    """Python convenience: qddot (n,) at one state; raises SingularMass instead of returning NaN.
    params: None (defaults), a dict by name, or a full vector in PARAMS order; a frozen
    parameter (FROZEN) cannot be passed."""
    q = np.ascontiguousarray(q, dtype=np.float64)
    qd = np.ascontiguousarray(qd, dtype=np.float64)
    if q.shape != (N_COORDS,) or qd.shape != (N_COORDS,):
        raise ValueError(f"{NAME}: q and qd must have {N_COORDS} entries ({', '.join(COORDS)})")
    p = resolve_params(PARAMS, DEFAULTS, params, NAME, frozen=FROZEN)
    H = np.empty((N_COORDS, N_COORDS))
    qdd = np.empty(N_COORDS)
    if forward_dynamics(q, qd, float(t), p, H, qdd) != OK:
        raise SingularMass(f"{NAME}: singular mass matrix H(q) at q = {q.tolist()}", state=q.copy())
    return qdd
'''


def factor_at_import(dyn) -> bool:
    """True when H is constant and every parameter it depends on has a default value."""
    if not dyn.mass_is_constant:
        return False
    used = {str(s) for s in dyn.native["H"].free_symbols}
    return all(d is not None for s, d in zip(dyn.params, dyn.model.defaults()) if s.name in used)


def forward_source(dyn) -> str:
    """Source of forward_dynamics and accelerations for this model (see the module docstring)."""
    if not factor_at_import(dyn):
        return _GENERAL + _ACCELERATIONS
    used = {str(s) for s in dyn.native["H"].free_symbols}
    checks = [f"p[{k}] == {float(d)!r}" for k, (s, d) in enumerate(zip(dyn.params, dyn.model.defaults()))
              if s.name in used]
    names = ", ".join(s.name for s in dyn.params if s.name in used) or "none"
    return _CONSTANT.format(used=names, test=" and ".join(checks) or "True") + _ACCELERATIONS
