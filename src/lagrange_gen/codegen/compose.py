"""Kernels built from other kernels instead of from their own symbolic expressions.

numba's compile time grows with the operations a kernel contains (about a millisecond each; kernel
compile times: ``lagrange-gen bench scale``, reports/scale.md), so symbolic work that two kernels
share is compiled twice. When the kernels that hold the shared part are emitted anyway, a kernel is
composed from them:

* momentum_rate_jacobian: d(dp/dt)/dqd = D(qd)^T + dQ/dqd, where D(w) = d(H(q) w)/dq is the
  kernel mass_matvec_dq; only d(dp/dt)/dq (and a nonzero dQ/dqd) stays symbolic.
* dynamics: rhs = dp/dt - Hdot qd with Hdot qd = D(qd) qd, so dynamics is mass_matrix,
  momentum_rate and mass_matvec_dq plus a matrix-vector product: no symbolic code of its own.
  It costs a third more per call (each kernel evaluates its own sines and cosines), so it is
  composed only when every requested method that calls dynamics also calls momentum_rate: the
  (q, p) methods, which evaluate forces through momentum_rate on their hot path and call
  dynamics only on the explicit path of a constant H.

Results equal the symbolic kernels to rounding (tests compare them).
"""

from __future__ import annotations

from .spec import KernelSpec, Output, default_kernels, kernel_table


def compositions(dyn, selected, needs) -> dict:
    """{kernel: reason} of the selected kernels to compose; needs {method: kern names}."""
    out = {}
    if dyn.has_transport:       # momentum_rate (canonical, with b) is not dT/dq - g + Q there
        return out
    if hasattr(dyn.jac, "columns"):     # graph models: the Jacobians are column loops already
        return out
    if "mass_matvec_dq" in selected and "momentum_rate_jacobian" in selected:
        out["momentum_rate_jacobian"] = "d/dqd part = mass_matvec_dq(q, qd)^T + dQ/dqd"
    # The steppers reach dynamics through the module function forward_dynamics (steppers/core/legendre.py
    # accel): a method naming either calls it. (Counting only "dynamics" would find no caller,
    # and the verlet/midpoint module would fall back to the symbolic dynamics: at 16 links about
    # a thousand more lines and a slower first compile of its kernels.)
    callers = [names for names in needs.values() if {"dynamics", "forward_dynamics"} & set(names)]
    # (not for H(q, t): rhs also holds -dH/dt qd, which the composition would miss)
    if (not dyn.mass_is_constant and not dyn.mass_depends_on_t and {"mass_matvec_dq", "momentum_rate"} <= set(selected)
            and callers and all("momentum_rate" in names for names in callers)):
        out["dynamics"] = "mass_matrix, momentum_rate - mass_matvec_dq(q, qd) qd"
    return out


def composed_spec(name, dyn) -> KernelSpec:
    n = dyn.n
    if name == "momentum_rate_jacobian":
        return KernelSpec(
            "momentum_rate_jacobian", ["q", "qd", "t", "p"],
            [Output("Jq", dyn.jac.native("dmom_dq")), Output("Jqd", dyn.jac.native("dQ_dqd"), accumulate=True)],
            doc="d(dp/dt)/dq and d(dp/dt)/dqd (n, n); the latter composed as D(qd)^T + dQ/dqd",
            prologue=["mass_matvec_dq(q, qd, t, p, Jqd)      # D(qd) = d(H qd)/dq",
                      f"for j in range({n}):",
                      f"    for l in range(j + 1, {n}):",
                      "        Jqd[j, l], Jqd[l, j] = Jqd[l, j], Jqd[j, l]"])
    if name == "dynamics":
        return KernelSpec(
            "dynamics", ["q", "qd", "t", "p"], [], out_args=["H", "rhs"],
            doc="H(q) (n, n) and rhs = Q - h - g (n,), so that H qddot = rhs; composed as "
                "rhs = dp/dt - D(qd) qd",
            prologue=["mass_matvec_dq(q, qd, t, p, H)        # H holds D(qd) until mass_matrix below",
                      "momentum_rate(q, qd, t, p, rhs)",
                      f"for j in range({n}):",
                      "    s = 0.0",
                      f"    for l in range({n}):",
                      "        s += H[j, l] * qd[l]",
                      "    rhs[j] -= s",
                      "mass_matrix(q, t, p, H)"])
    raise KeyError(f"no composed form of kernel {name!r}")


def make_kernels(dyn, names=None, composed=()) -> list[KernelSpec]:
    """KernelSpecs of ``names`` (default: default_kernels) in the fixed table order; the kernels
    in ``composed`` are built from other kernels (composed_spec) instead of symbolically."""
    table = kernel_table(dyn)
    wanted = set(default_kernels(dyn) if names is None else names)
    unknown = sorted(wanted - set(table))
    if unknown:
        raise KeyError(f"no kernel named {', '.join(unknown)}")
    return [composed_spec(name, dyn) if name in composed else build()
            for name, build in table.items() if name in wanted]
