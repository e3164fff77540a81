"""Forward dynamics and the Python convenience `accelerations` of a generated module.

Three variants, chosen from the model:

* H(q) depends on q and n is small (n <= UNROLL_MAX): one kernel computes the entries of H and
  rhs into local variables (one CSE pass over both) and solves H qdd = rhs by an unrolled
  LDL^T factorization written out for this n, with the same singularity test as
  linalg.cholesky_inplace. No array is written but qdd.
* H(q) depends on q, larger n: every call fills H and factors it (Cholesky, in numba).
* H(q) depends on q and the kinetic energy is a tree of joints (derive/recursive.py), and the
  articulated-body algorithm takes fewer operations than H and rhs: forward_dynamics is ABA
  written out for this tree, O(n), with no H; forward_dynamics_torques too, and
  forward_dynamics_jacobian is d qdd/dx = -H^-1 d(inverse dynamics)/dx at the solved qdd, the
  inverse dynamics (RNEA) differentiated one column at a time.
* H is constant: it is factored once, at import, for the default values of the parameters it
  depends on (MASS_FACTOR, lower Cholesky factor L with H = L L^T); a call evaluates only
  rhs = Q - h - g and does two triangular solves, unless the caller passes other values for
  those parameters, in which case H is formed and factored as in the general case.
"""

from __future__ import annotations

import symengine as se

from ..derive.recursive import operation_count
from ..derive.structured import SEED_PREFIX
from .emit import local_name, render_column_kernel, render_kernel
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
    # the arguments are this function's own, of the right shapes: the kernel's call without
    # its check from Python (set by check_python_calls)
    if _forward_dynamics_unchecked(q, qd, float(t), p, H, qdd) != OK:
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


_RECURSIVE_JACOBIAN = '''

@njit(**KERNEL_OPTIONS)
def forward_dynamics_jacobian(q, qd, t, p, H, qdd, Jq, Jqd, W):
    """qdd (n,) by ABA and its derivatives Jq = d qdd/dq, Jqd = d qdd/dqd (n, n): with tau the
    inverse dynamics, H J = -d tau/dx at the solved qdd (tau(q, qd, qdd(q, qd)) is the model's
    own force, constant). H and W (n, n) are workspace. Returns OK or SINGULAR_MASS."""
    status = forward_dynamics(q, qd, t, p, H, qdd)
    if status != OK:
        return status
    mass_matrix(q, t, p, H)
    if not cholesky_inplace(H):
        return SINGULAR_MASS
    inverse_dynamics_jacobian(q, qd, qdd, t, p, Jq, Jqd)
    column = W[0]
    for J in (Jq, Jqd):
        for j in range(N_COORDS):
            for i in range(N_COORDS):
                column[i] = -J[i, j]
            cholesky_solve_inplace(H, column)
            for i in range(N_COORDS):
                J[i, j] = column[i]
    return OK
'''


def pivot_check_lines(count, name="D"):
    """Statements returning SINGULAR_MASS unless every ABA pivot (locals D_0 ...) is positive
    beyond SINGULAR_RTOL times the largest (the test of linalg.cholesky_inplace), else OK."""
    if count == 0:
        return ["return OK"]
    pivots = [local_name(name, i) for i in range(count)]
    scale = f"max({', '.join(f'abs({d})' for d in pivots)})" if count > 1 else f"abs({pivots[0]})"
    return [f"scale = {scale}", "if not (scale > 0.0 and scale < math.inf):", "    return SINGULAR_MASS",
            "tiny = SINGULAR_RTOL * scale",
            f"if not ({' and '.join(f'{d} > tiny' for d in pivots)}):", "    return SINGULAR_MASS", "return OK"]


def aba_text(dyn, torques=False) -> str:
    """forward_dynamics (or forward_dynamics_torques, tau (n,) added to the model's forces) as
    the articulated-body algorithm of dyn.recursive, written out."""
    o, rec = dyn.ops, dyn.recursive
    tau = o.symbols(dyn.aux["w"]) if torques else None
    qdd, pivots = rec.forward_dynamics(tau)
    name = "forward_dynamics_torques" if torques else "forward_dynamics"
    args = ["q", "qd", "tau", "t", "p"] if torques else ["q", "qd", "t", "p"]
    what = "rhs + tau for generalized forces tau (n,) added to the model's own (joint torques)" if torques else "rhs"
    spec = KernelSpec(
        name, args, [Output("qdd", o.column(qdd)), Output("D", o.column(pivots), local=True)],
        doc=(f"Solve H(q) qdd = {what} by the articulated-body algorithm written out for this "
             "tree (no H is formed); H (n, n) is not used (kept for the common signature), qdd (n,) "
             "the output. Returns OK, or SINGULAR_MASS when a joint's articulated inertia D is not "
             "numerically positive"),
        out_args=["H", "qdd"], epilogue=pivot_check_lines(len(pivots)))
    return render_kernel(spec, Inputs(dyn)).function


def inverse_dynamics_jacobian_text(dyn) -> str:
    """inverse_dynamics_jacobian(q, qd, qdd, t, p, Jq, Jqd): d tau/dq and d tau/dqd (n, n) of
    the inverse dynamics (RNEA) at given accelerations, one tangent pass per column."""
    o, rec, graph = dyn.ops, dyn.recursive, dyn.ops.graph
    tau = rec.inverse_dynamics(o.symbols(dyn.aux["qdd"]))
    seeds = [se.Symbol(f"{SEED_PREFIX}{i}") for i in range(dyn.n)]
    columns = [(name, seeds, graph.tangents(tau, dict(zip(xs, seeds))))
               for name, xs in (("Jq", o.symbols(dyn.q)), ("Jqd", o.symbols(dyn.qd)))]
    spec = KernelSpec("inverse_dynamics_jacobian", ["q", "qd", "qdd", "t", "p"],
                      doc="d tau/dq and d tau/dqd (n, n) of the inverse dynamics tau = H qdd + h + g - Q "
                          "at accelerations qdd (n,), column by column",
                      out_args=["Jq", "Jqd"], columns=columns)
    return render_column_kernel(spec, Inputs(dyn)).function


def uses_aba(dyn) -> bool:
    """True when forward dynamics is the articulated-body algorithm: a tree of joints whose ABA
    has fewer operations than H and rhs (what forward_dynamics evaluates otherwise)."""
    rec = dyn.recursive
    if rec is None or dyn.mass_is_constant:
        return False
    graph = dyn.ops.graph
    qdd, pivots = rec.forward_dynamics()
    return operation_count(graph, qdd + pivots) < operation_count(graph, list(dyn.native["H"]) + list(dyn.native["rhs"]))


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
    if uses_aba(dyn):
        return "\n\n\n".join([aba_text(dyn), aba_text(dyn, torques=True), inverse_dynamics_jacobian_text(dyn)]) + \
            "\n" + _ACCELERATIONS + _RECURSIVE_JACOBIAN
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
