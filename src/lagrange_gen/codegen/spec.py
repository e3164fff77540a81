"""KernelSpec: what one generated kernel computes, before printing."""

from __future__ import annotations

from dataclasses import dataclass, field

import sympy as sp


@dataclass
class Output:
    """An in-place output array of a kernel.

    name: argument name; matrix: sympy Matrix whose shape is the array's shape (a column vector
    becomes a 1-D array); symmetric: only the upper triangle is computed, then mirrored.
    """

    name: str
    matrix: sp.Matrix
    symmetric: bool = False

    @property
    def is_vector(self):
        return self.matrix.shape[1] == 1 and self.name not in _ALWAYS_2D

    @property
    def shape(self):
        return (self.matrix.shape[0],) if self.is_vector else tuple(self.matrix.shape)


_ALWAYS_2D = {"H", "J", "Jq", "Jqd", "dJw", "dJTlam", "out_mat", "G", "coef"}


@dataclass
class KernelSpec:
    """One kernel: ``def name(*args, *outputs)`` filling outputs in place, or returning ``result``.

    args: input argument names in order (q, qd, t, p, w, lam); doc: one line for the docstring.
    """

    name: str
    args: list
    outputs: list = field(default_factory=list)
    result: sp.Expr | None = None
    doc: str = ""


def make_kernels(dyn) -> list[KernelSpec]:
    """The symbolic kernels of a model, in a fixed order (see DESIGN.md section 5)."""
    jac = dyn.jac
    kernels = [
        KernelSpec("mass_matrix", ["q", "p"], [Output("H", dyn.H, symmetric=True)],
                   doc="H(q) (n, n), the generalized inertia"),
        KernelSpec("dynamics", ["q", "qd", "t", "p"],
                   [Output("H", dyn.H, symmetric=True), Output("rhs", dyn.rhs)],
                   doc="H(q) (n, n) and rhs = Q - h - g (n,), so that H qddot = rhs"),
        KernelSpec("energy", ["q", "qd", "t", "p"], result=dyn.E, doc="E = T + V (scalar)"),
        KernelSpec("momentum_rate", ["q", "qd", "t", "p"], [Output("out", dyn.momentum_rate)],
                   doc="dp/dt = dT/dq - dV/dq + Q (n,) for p = H(q) qd"),
        KernelSpec("rhs_jacobian", ["q", "qd", "t", "p"],
                   [Output("Jq", jac["drhs_dq"]), Output("Jqd", jac["drhs_dqd"])],
                   doc="d rhs/dq and d rhs/dqd (n, n)"),
        KernelSpec("momentum_rate_jacobian", ["q", "qd", "t", "p"],
                   [Output("Jq", jac["dmom_dq"]), Output("Jqd", jac["dmom_dqd"])],
                   doc="d(dp/dt)/dq and d(dp/dt)/dqd (n, n)"),
        KernelSpec("mass_matvec_dq", ["q", "w", "p"], [Output("out_mat", jac["dHw_dq"])],
                   doc="d(H(q) w)/dq (n, n) for a vector w (n,)"),
        KernelSpec("constraints", ["q", "qd", "p"],
                   [Output("phi", dyn.Phi), Output("J", dyn.J), Output("gamma", dyn.gamma)],
                   doc="Phi(q) (m,), J = dPhi/dq (m, n), gamma = -(dJ/dt) qd (m,)"),
        KernelSpec("constraint_dq", ["q", "w", "lam", "p"],
                   [Output("dJw", jac["dJw_dq"]), Output("dJTlam", jac["dJTlam_dq"], symmetric=True)],
                   doc="d(J w)/dq (m, n) and d(J^T lam)/dq (n, n)"),
        KernelSpec("elements", ["q", "p"],
                   [Output("s", dyn.elem_s), Output("G", dyn.elem_grad), Output("coef", dyn.elem_coef)],
                   doc="nonsmooth elements: strains s (ne,), gradients G = ds/dq (ne, n), "
                       "coef (ne, 3) = (stiffness, threshold, 0) or (friction bound, 0, 1)"),
        KernelSpec("elements_hessian", ["q", "we", "p"], [Output("out_mat", dyn.elem_hess_w, symmetric=True)],
                   doc="sum_e we[e] d2 s_e/dq2 (n, n) for weights we (ne,)"),
    ]
    return kernels
