"""Forward dynamics and the Python convenience `accelerations` of a generated module.

Three variants, chosen from the model:

* H(q) depends on q and n is small (n <= UNROLL_MAX): one kernel computes the entries of H and
  rhs into local variables (one CSE pass over both) and solves H qdd = rhs by an unrolled
  LDL^T factorization written out for this n, with the same singularity test as
  linalg.cholesky_inplace. No array is written but qdd.
* H(q) depends on q, larger n: every call fills H and factors it (Cholesky, in numba).
* H is constant: it is factored once, at import, for the default values of the parameters it
  depends on (MASS_FACTOR, lower Cholesky factor L with H = L L^T); a call evaluates only
  rhs = Q - h - g and does two triangular solves, unless the caller passes other values for
  those parameters, in which case H is formed and factored as in the general case.
"""

from __future__ import annotations

from .emit import local_name, render_kernel
from .printer import Inputs
from .spec import KernelSpec, Output

#: Largest n whose forward dynamics is emitted as an unrolled LDL^T solve (module docstring).
UNROLL_MAX = 4

_GENERAL = '''@njit(**KERNEL_OPTIONS)
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
    mass_matrix(np.zeros(N_COORDS), 0.0, p, L)
    if not cholesky_inplace(L):
        raise ValueError(f"{{NAME}}: the constant mass matrix is not positive definite at the defaults")
    return np.tril(L)          # the upper triangle still held H


# H does not depend on q: factored once, here, for the defaults of the parameters it uses
# ({used}). numba freezes this array into forward_dynamics as a constant.
MASS_FACTOR = _factor_mass_matrix(DEFAULT_PARAMS)


@njit(**KERNEL_OPTIONS)
def forward_dynamics(q, qd, t, p, H, qdd):
    """Solve H qdd = rhs with the constant H: by MASS_FACTOR (no factorization) when the
    parameters H depends on have their default values, else by factoring H into the workspace
    H (n, n). qdd (n,) is the output. Returns OK, or SINGULAR_MASS."""
    rhs(q, qd, t, p, qdd)
    if {test}:
        cholesky_solve_inplace(MASS_FACTOR, qdd)
        return OK
    mass_matrix(q, t, p, H)
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
    # the defaults need no checking: DEFAULT_PARAMS was built from them at import
    p = DEFAULT_PARAMS if params is None and None not in DEFAULTS else resolve_params(
        PARAMS, DEFAULTS, params, NAME, frozen=FROZEN)
    H = np.empty((N_COORDS, N_COORDS))
    qdd = np.empty(N_COORDS)
    if forward_dynamics(q, qd, float(t), p, H, qdd) != OK:
        raise SingularMass(f"{NAME}: singular mass matrix H(q) at q = {q.tolist()}", state=q.copy())
    return qdd
'''


_WITH_TORQUES = '''

@njit(**KERNEL_OPTIONS)
def forward_dynamics_torques(q, qd, tau, t, p, H, qdd):
    """Solve H(q) qdd = rhs + tau for generalized forces tau (n,) added to the model's own
    (joint torques); H (n, n) is workspace, qdd (n,) the output. Returns OK or SINGULAR_MASS."""
    dynamics(q, qd, t, p, H, qdd)
    for i in range(N_COORDS):
        qdd[i] += tau[i]
    if not cholesky_inplace(H):
        return SINGULAR_MASS
    cholesky_solve_inplace(H, qdd)
    return OK


@njit(**KERNEL_OPTIONS)
def forward_dynamics_jacobian(q, qd, t, p, H, qdd, Jq, Jqd, W):
    """qdd (n,) = H^-1 rhs and its derivatives Jq = d qdd/dq, Jqd = d qdd/dqd (n, n):
    H Jq = d rhs/dq - d(H w)/dq at w = qdd, H Jqd = d rhs/dqd, solved with the factor of H.
    H and W (n, n) are workspace. Returns OK or SINGULAR_MASS."""
    dynamics(q, qd, t, p, H, qdd)
    if not cholesky_inplace(H):
        return SINGULAR_MASS
    cholesky_solve_inplace(H, qdd)
    rhs_jacobian(q, qd, t, p, Jq, Jqd)
    mass_matvec_dq(q, qdd, t, p, W)
    for i in range(N_COORDS):
        for j in range(N_COORDS):
            Jq[i, j] -= W[i, j]
    column = W[0]                 # W is free now: its first row holds one column at a time
    for J in (Jq, Jqd):
        for j in range(N_COORDS):
            for i in range(N_COORDS):
                column[i] = J[i, j]
            cholesky_solve_inplace(H, column)
            for i in range(N_COORDS):
                J[i, j] = column[i]
    return OK
'''


def factor_at_import(dyn) -> bool:
    """True when H is constant and every parameter it depends on has a default value."""
    if not dyn.mass_is_constant:
        return False
    used = {str(s) for s in dyn.native["H"].free_symbols}
    return all(d is not None for s, d in zip(dyn.params, dyn.model.defaults()) if s.name in used)


def unrolled_solve_lines(n, H="H", b="rhs", out="qdd"):
    """Statements solving H x = b (n x n, SPD) by LDL^T written out for this n, reading the
    locals H_j_k (upper triangle, j <= k) and b_i, writing out[i]. They return SINGULAR_MASS
    exactly where linalg.cholesky_inplace fails: diagonal scale not positive and finite, or a
    pivot d_j <= SINGULAR_RTOL * scale (d_j is the square of Cholesky's pivot)."""
    def Hu(j, k):
        return local_name(H, min(j, k), max(j, k))
    diag = ", ".join(f"abs({Hu(i, i)})" for i in range(n))
    lines = [f"scale = {f'max({diag})' if n > 1 else diag}",
             "if not (scale > 0.0 and scale < math.inf):", "    return SINGULAR_MASS",
             "tiny = SINGULAR_RTOL * scale"]
    for j in range(n):
        for k in range(j):                       # e_j_k = L_j_k d_k, used by row j and below
            lines.append(f"e_{j}_{k} = L_{j}_{k} * d_{k}")
        lines.append(f"d_{j} = {Hu(j, j)}" + "".join(f" - L_{j}_{k} * e_{j}_{k}" for k in range(j)))
        lines += [f"if not (d_{j} > tiny):", "    return SINGULAR_MASS"]
        for i in range(j + 1, n):
            num = Hu(i, j) + "".join(f" - L_{i}_{k} * e_{j}_{k}" for k in range(j))
            lines.append(f"L_{i}_{j} = ({num}) / d_{j}" if j else f"L_{i}_{j} = {num} / d_{j}")
    for i in range(n):                           # L y = b, then y / d, then L^T x = y / d
        lines.append(f"y_{i} = {local_name(b, i)}" + "".join(f" - L_{i}_{k} * y_{k}" for k in range(i)))
    for i in reversed(range(n)):
        lines.append(f"x_{i} = y_{i} / d_{i}" + "".join(f" - L_{k}_{i} * x_{k}" for k in range(i + 1, n)))
    lines += [f"{out}[{i}] = x_{i}" for i in range(n)]
    return lines + ["return OK"]


def unrolled_forward_text(dyn) -> str:
    """forward_dynamics as one kernel: H and rhs into locals, then the unrolled solve."""
    nat = dyn.native
    spec = KernelSpec(
        "forward_dynamics", ["q", "qd", "t", "p"],
        [Output("H", nat["H"], symmetric=True, local=True), Output("rhs", nat["rhs"], local=True)],
        doc=("Solve H(q) qdd = rhs = Q - h - g by LDL^T written out for n = "
             f"{dyn.n}; H (n, n) is not used (kept for the common signature), qdd (n,) the "
             "output. Returns OK, or SINGULAR_MASS when H is not numerically positive definite"),
        out_args=["H", "qdd"], epilogue=unrolled_solve_lines(dyn.n))
    return render_kernel(spec, Inputs(dyn)).function


def forward_source(dyn) -> str:
    """Source of forward_dynamics and accelerations for this model (see the module docstring)."""
    torques = _WITH_TORQUES if hasattr(dyn.jac, "inverse_dynamics") and not dyn.mass_is_constant else ""
    if not factor_at_import(dyn):
        if not dyn.mass_is_constant and dyn.n <= UNROLL_MAX:
            return unrolled_forward_text(dyn) + "\n" + _ACCELERATIONS + torques
        return _GENERAL + _ACCELERATIONS + torques
    used = {str(s) for s in dyn.native["H"].free_symbols}
    checks = [f"p[{k}] == {float(d)!r}" for k, (s, d) in enumerate(zip(dyn.params, dyn.model.defaults()))
              if s.name in used]
    names = ", ".join(s.name for s in dyn.params if s.name in used) or "none"
    return _CONSTANT.format(used=names, test=" and ".join(checks) or "True") + _ACCELERATIONS
