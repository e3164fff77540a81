"""KernelSpec: what one generated kernel computes, before printing."""

from __future__ import annotations

from dataclasses import dataclass, field

import symengine as se
import sympy as sp

from ..jit.kernel_abi import ALWAYS_2D
from ..derive.nonholonomic import constraint_gamma_jacobians, nonholonomic_jacobians
from ..derive.structured import SEED_PREFIX
from ..derive.recursive import column_operation_counts, operation_count
from ..model.symbols import Parameter


@dataclass
class Output:
    """An in-place output array of a kernel.

    name: argument name; matrix: sympy Matrix whose shape is the array's shape (a column vector
    becomes a 1-D array); symmetric: only the upper triangle is computed, then mirrored;
    accumulate: the kernel's prologue already filled the array and the nonzero entries are added
    to it (``+=``; zero entries are left alone); local: no array, each entry is assigned to a
    local variable (``H_0_1``, ``rhs_1``; symmetric: upper triangle only) that the kernel's
    epilogue reads (codegen.forward's unrolled solve).
    """

    name: str
    matrix: sp.Matrix
    symmetric: bool = False
    accumulate: bool = False
    local: bool = False

    @property
    def is_vector(self):
        return self.matrix.shape[1] == 1 and self.name not in ALWAYS_2D

    @property
    def shape(self):
        return (self.matrix.shape[0],) if self.is_vector else tuple(self.matrix.shape)




@dataclass
class KernelSpec:
    """One kernel: ``def name(*args, *outputs)`` filling outputs in place, or returning ``result``.

    args: input argument names in order (q, qd, t, p, w, lam); doc: one line for the docstring.
    out_args: output argument names when they are not exactly the symbolic outputs' names (a
    composed kernel, see codegen.compose); prologue: statements run first (calls of other kernels,
    numeric loops); epilogue: statements run last (they may ``return``). columns: for a
    Jacobian written as a loop over its columns (graph models, emit.render_column_kernel),
    [(output name, seeds, column expressions)] from derive.structured.GraphJacobians.columns.
    """

    name: str
    args: list
    outputs: list = field(default_factory=list)
    result: sp.Expr | None = None
    doc: str = ""
    out_args: list | None = None
    prologue: list = field(default_factory=list)
    epilogue: list = field(default_factory=list)
    columns: list = field(default_factory=list)

    @property
    def signature(self):
        return self.args + (self.out_args if self.out_args is not None else [o.name for o in self.outputs])


#: Kernels every generated module has, whatever the methods: forward_dynamics/accelerations
#: (dynamics), the saved energy (energy) and the Legendre transform (mass_matrix).
CORE_KERNELS = ("mass_matrix", "dynamics", "energy")


def kernel_table(dyn) -> dict:
    """{kernel name: function returning its KernelSpec}, in a fixed order. Specs are built on
    demand: a Jacobian is only derived when its kernel is emitted."""
    nat, jac = dyn.native, dyn.jac.native
    table = {
        "mass_matrix": lambda: KernelSpec("mass_matrix", ["q", "t", "p"], [Output("H", nat["H"], symmetric=True)],
                                          doc="H(q, t) (n, n), the generalized inertia"),
        "dynamics": lambda: KernelSpec(
            "dynamics", ["q", "qd", "t", "p"], [Output("H", nat["H"], symmetric=True), Output("rhs", nat["rhs"])],
            doc="H(q) (n, n) and rhs = Q - h - g (n,), so that H qddot = rhs"),
        "rhs": lambda: KernelSpec("rhs", ["q", "qd", "t", "p"], [Output("out", nat["rhs"])],
                                  doc="rhs = Q - h - g (n,) alone (for a constant, pre-factored H)"),
        "energy": lambda: KernelSpec("energy", ["q", "qd", "t", "p"], result=nat["E"],
                                     doc="E = T2 - T0 + V (scalar; T + V when T is scleronomic)"),
        "momentum_rate": lambda: KernelSpec("momentum_rate", ["q", "qd", "t", "p"], [Output("out", nat["momentum_rate"])],
                                            doc="dp/dt = dL/dq + Q_nc (n,) for the canonical momentum p = H qd + b"),
        "power": lambda: KernelSpec(
            "power", ["q", "qd", "t", "p"], [Output("out", nat["power"])],
            doc="(P, dP/dq, dP/dqd, dP/dt) (2n + 2,) with P = qd . Q_nc - dL/dt = dE/dt, the "
                "power whose integral W closes E - E0 - W = 0"),
        "transport": lambda: KernelSpec(
            "transport", ["q", "t", "p"], [Output("out", nat["b"], accumulate=True)],
            doc="out += b(q, t) (n,), the T1 = b . qd part of T: p = H qd + b (nothing when T1 = 0)"),
        "transport_dq": lambda: KernelSpec(
            "transport_dq", ["q", "t", "p"], [Output("out_mat", nat["db"], accumulate=True)],
            doc="out_mat += db/dq (n, n) (nothing when T1 = 0)"),
        "rhs_jacobian": lambda: KernelSpec(
            "rhs_jacobian", ["q", "qd", "t", "p"], [Output("Jq", jac("drhs_dq")), Output("Jqd", jac("drhs_dqd"))],
            doc="d rhs/dq and d rhs/dqd (n, n)"),
        "momentum_rate_jacobian": lambda: KernelSpec(
            "momentum_rate_jacobian", ["q", "qd", "t", "p"], [Output("Jq", jac("dmom_dq")), Output("Jqd", jac("dmom_dqd"))],
            doc="d(dp/dt)/dq and d(dp/dt)/dqd (n, n)"),
        "mass_matvec_dq": lambda: KernelSpec("mass_matvec_dq", ["q", "w", "t", "p"], [Output("out_mat", jac("dHw_dq"))],
                                             doc="d(H(q) w)/dq (n, n) for a vector w (n,)"),
        "constraints": lambda: KernelSpec(
            "constraints", ["q", "qd", "t", "p"],
            [Output("phi", nat["Phi"]), Output("J", nat["J"]), Output("gamma", nat["gamma"])],
            doc="Phi(q, t) (m,), J = dPhi/dq (m, n), gamma (m,) with J qdd = gamma along a motion"),
        "constraint_rate": lambda: KernelSpec(
            "constraint_rate", ["q", "t", "p"], [Output("out", nat["Phi_t"])],
            doc="dPhi/dt (m,): the velocity constraint is J qd + dPhi/dt = 0 (zero when scleronomic)"),
        "constraint_dq": lambda: KernelSpec(
            "constraint_dq", ["q", "w", "lam", "t", "p"],
            [Output("dJw", jac("dJw_dq")), Output("dJTlam", jac("dJTlam_dq"), symmetric=True)],
            doc="d(J w)/dq (m, n) and d(J^T lam)/dq (n, n)"),
        "elements": lambda: KernelSpec(
            "elements", ["q", "p"],
            [Output("s", nat["elem_s"]), Output("G", nat["elem_grad"]), Output("coef", nat["elem_coef"])],
            doc="nonsmooth elements: strains s (ne,), gradients G = ds/dq (ne, n), "
                "coef (ne, 3) = (stiffness, threshold, 0) or (friction bound, 0, 1)"),
        "elements_hessian": lambda: KernelSpec(
            "elements_hessian", ["q", "we", "p"], [Output("out_mat", nat["elem_hess_w"], symmetric=True)],
            doc="sum_e we[e] d2 s_e/dq2 (n, n) for weights we (ne,)"),
        "events": lambda: KernelSpec(
            "events", ["q", "qd", "t", "p"], [Output("out", _column(event_functions(dyn)))],
            doc="event functions g (n_events,) in EVENT_NAMES order, whose zero crossings "
                "steppers/core/events.py locates"),
    }
    table.update(io_kernels(dyn))
    table.update(parameter_kernels(dyn))
    table.update(contact_kernels(dyn))
    table.update(nonholonomic_kernels(dyn))
    if hasattr(dyn.jac, "columns"):
        table.update(column_kernels(dyn))
        table.update(robot_kernels(dyn))
        table.update(recursive_mass_kernels(dyn))
    return table


#: The kernels of a model built from bodies that controllers and robotics users call.
ROBOT_KERNELS = ("inverse_dynamics", "gravity_forces", "bias_forces")


def robot_kernels(dyn) -> dict:
    """inverse_dynamics, gravity_forces and bias_forces of a graph model (each one pass over
    the graph, cheaper than dynamics: no mass matrix is formed): by RNEA over the tree of joints
    (derive/recursive.py) where it has fewer operations than the tangent of the momentum."""
    nat, o = dyn.native, dyn.ops
    qdd = o.symbols(dyn.aux["qdd"])
    tau, minus_rhs = dyn.jac.inverse_dynamics(qdd), [-e for e in nat["rhs"]]
    if dyn.recursive is not None:
        graph = o.graph
        rnea, bias = dyn.recursive.inverse_dynamics(qdd), dyn.recursive.inverse_dynamics([0] * dyn.n)
        if operation_count(graph, rnea) < operation_count(graph, tau):
            tau = rnea
        if operation_count(graph, bias) < operation_count(graph, minus_rhs):
            minus_rhs = bias
    minus_rhs = o.column(minus_rhs)
    return {
        "inverse_dynamics": lambda: KernelSpec(
            "inverse_dynamics", ["q", "qd", "qdd", "t", "p"],
            [Output("tau", o.column(tau))],
            doc="tau = H(q) qdd + h(q, qd) + g(q) - Q (n,): the generalized forces that give the "
                "accelerations qdd (n,) (RNEA's answer)"),
        "gravity_forces": lambda: KernelSpec(
            "gravity_forces", ["q", "t", "p"], [Output("out", nat["g"])],
            doc="g(q) = dV/dq (n,)"),
        "bias_forces": lambda: KernelSpec(
            "bias_forces", ["q", "qd", "t", "p"], [Output("out", minus_rhs)],
            doc="h(q, qd) + g(q) - Q (n,): tau at qdd = 0 (velocity terms, gravity and the "
                "model's own forces)"),
    }


#: The parameter derivatives of the kernels a fixed-step method's step uses: emitted only for a
#: module generated with sensitivities (codegen.needs.select_kernels), never in a kernel library.
SENSITIVITY_KERNELS = ("rhs_dp", "momentum_rate_dp", "mass_matvec_dp", "transport_dp")


def parameter_kernels(dyn) -> dict:
    """d rhs/dp, d momentum_rate/dp, d(H(q) w)/dp and d b/dp (n, n_params; b: the T1 = b . qd
    term of T, zero on most models), one column per entry of p
    (PARAMS order, inputs included): what forward sensitivities (steppers/sensitivity.py) add to
    the step's state Jacobians. A model built from bodies differentiates through its graph, one
    tangent pass along the parameters written as a loop over the columns (as column_kernels);
    others write the Jacobian out."""
    o, nat, n = dyn.ops, dyn.native, dyn.n
    params, w = o.symbols(dyn.params), o.symbols(dyn.aux["w"])
    H = nat["H"]

    def Hw():
        return [sum((H[i, j] * w[j] for j in range(n)), o.native(0)) for i in range(n)]

    sources = {"rhs_dp": (["q", "qd", "t", "p"], lambda: list(nat["rhs"]),
                          "d rhs/dp (n, n_params), rhs = Q - h - g"),
               "momentum_rate_dp": (["q", "qd", "t", "p"], lambda: list(nat["momentum_rate"]),
                                    "d momentum_rate/dp (n, n_params)"),
               "mass_matvec_dp": (["q", "w", "t", "p"], Hw,
                                  "d(H(q) w)/dp (n, n_params) for a vector w (n,)"),
               "transport_dp": (["q", "t", "p"], lambda: list(nat["b"]),
                                "d b/dp (n, n_params) of the T1 = b(q, t) . qd term of T")}
    graph = getattr(o, "graph", None) if hasattr(dyn.jac, "columns") else None
    table = {}
    for name, (args, values, doc) in sources.items():
        def build(name=name, args=args, values=values, doc=doc):
            if graph is None or not params:
                return KernelSpec(name, args, [Output("Jp", o.jacobian(values(), params))], doc=doc)
            seeds = [se.Symbol(f"{SEED_PREFIX}{i}") for i in range(len(params))]
            column = graph.tangents(values(), dict(zip(params, seeds)))
            return KernelSpec(name, args, out_args=["Jp"], columns=[("Jp", seeds, column)],
                              doc=f"{doc}, column by column (one tangent pass along the parameters)")
        table[name] = build
    return table


def contact_kernels(dyn) -> dict:
    """The ``contacts``, ``contact_bias`` and ``contact_rates`` kernels of a model with unilateral
    contacts ({} without any); local rows (normal (c), tangent 1 (c), tangent 2 (c))."""
    if not dyn.n_contacts:
        return {}
    nat = dyn.native
    return {"contact_rates": lambda: KernelSpec(
        "contact_rates", ["q", "qd", "t", "p"], [Output("out", nat["contact_rate"])],
        doc="(3c,): the local accelerations are W qdd + these (dW/dt qd and a moving surface's "
            "time derivatives)"),
            "contact_bias": lambda: KernelSpec(
        "contact_bias", ["q", "t", "p"], [Output("out", nat["contact_bias"])],
        doc="(dg/dt, b_T1, b_T2) (3c,): the local velocities are W qd + these (a moving surface; "
            "zero for fixed ones)"),
            "contacts": lambda: KernelSpec(
        "contacts", ["q", "t", "p"],
        [Output("gap", nat["contact_gap"]), Output("WN", nat["contact_WN"]),
         Output("WT", nat["contact_WT"]), Output("coef", nat["contact_coef"])],
        doc="unilateral contacts: gaps g (c,), W_N = dg/dq (c, n), W_T = d slip/d qd (2c, n: "
            "tangent 1 rows, then tangent 2), "
            "coef (c, 2) = (restitution, friction)")}


#: The kernels a model with nonholonomic constraints gets for lagrange_gen.linearize (about a
#: steady motion: the derivatives of both kinds of constraint rows along it).
NONHOLONOMIC_LINEARIZE = ("rhs_jacobian", "mass_matvec_dq", "nonholonomic_dq")
CONSTRAINED_NONHOLONOMIC_LINEARIZE = ("constraint_dq", "constraint_gamma_dq")


def nonholonomic_kernels(dyn) -> dict:
    """The ``nonholonomic`` kernel of a model with velocity constraints and the derivatives
    linearize needs (``nonholonomic_dq``; ``constraint_gamma_dq`` with holonomic constraints
    too). Without velocity constraints: a ``nonholonomic`` kernel of 0 rows for a model with
    contacts (moreau_jean treats velocity constraints beside contacts and reaches it), else {}."""
    nat, o = dyn.native, dyn.ops
    if not dyn.n_nonholonomic:
        return {"nonholonomic": lambda: _nonholonomic_kernel(nat)} if dyn.n_contacts else {}
    q, qd = o.symbols(dyn.q), o.symbols(dyn.qd)

    def derivatives():
        d = nonholonomic_jacobians(o, nat, q, qd, o.symbols(dyn.aux["w"]), o.symbols(dyn.aux["mu"]))
        return KernelSpec(
            "nonholonomic_dq", ["q", "qd", "w", "mu", "t", "p"],
            [Output("dAw", d["dAw"]), Output("dATmu", d["dATmu"]), Output("dc", d["dc"]),
             Output("dgamma_dq", d["dgamma_dq"]), Output("dgamma_dqd", d["dgamma_dqd"])],
            doc="d(A w)/dq (r, n), d(A^T mu)/dq (n, n), d(A qd + b)/dq (r, n), d gamma/dq and "
                "d gamma/dqd (r, n) of the nonholonomic constraints")

    def gamma_derivatives():
        d = constraint_gamma_jacobians(o, nat, q, qd)
        return KernelSpec(
            "constraint_gamma_dq", ["q", "qd", "t", "p"],
            [Output("dgamma_dq", d["dgamma_dq"]), Output("dgamma_dqd", d["dgamma_dqd"])],
            doc="d gamma/dq and d gamma/dqd (m, n) of the holonomic constraints (J qdd = gamma)")

    table = {"nonholonomic": lambda: _nonholonomic_kernel(nat), "nonholonomic_dq": derivatives}
    if dyn.m:
        table["constraint_gamma_dq"] = gamma_derivatives
    return table


def _nonholonomic_kernel(nat):
    return KernelSpec(
        "nonholonomic", ["q", "qd", "t", "p"],
        [Output("A", nat["nh_A"]), Output("b", nat["nh_b"]), Output("gamma", nat["nh_gamma"])],
        doc="nonholonomic constraints A qd + b = 0: A(q, t) (r, n), b(q, t) (r,), gamma (r,) "
            "with A qdd = gamma along a motion")


def column_kernels(dyn) -> dict:
    """The Newton Jacobian kernels of a graph model as loops over their columns (same names,
    arguments and outputs as the written-out ones of kernel_table): tangents of the Lagrangian
    graph's rhs, momentum_rate or H w, or, for a tree of joints, of the recursive programs
    (derive/recursive.py RecursiveDynamics.columns) where those have fewer operations
    (jacobian_columns)."""
    docs = {"rhs_jacobian": (["q", "qd", "t", "p"], "d rhs/dq and d rhs/dqd (n, n)"),
            "momentum_rate_jacobian": (["q", "qd", "t", "p"], "d(dp/dt)/dq and d(dp/dt)/dqd (n, n)"),
            "mass_matvec_dq": (["q", "w", "t", "p"], "d(H(q) w)/dq (n, n) for a vector w (n,)")}
    out = {}
    for name, (args, doc) in docs.items():
        def build(name=name, args=args, doc=doc):
            columns, source = jacobian_columns(dyn, name)
            how = f" of {source}" if source else ""
            return KernelSpec(name, args, doc=f"{doc}, column by column (one tangent pass{how} per column)",
                              out_args=[c[0] for c in columns], columns=columns)
        out[name] = build
    return out


#: What each column kernel differentiates when it comes from the recursive programs.
RECURSIVE_SOURCES = {"rhs_jacobian": "the bias RNEA, rhs = -tau(q, qd, 0)",
                     "mass_matvec_dq": "RNEA at rest, H w = tau(q, 0, w) without model forces",
                     "momentum_rate_jacobian": "Hdot qd - tau(q, qd, 0) by RNEA"}


def jacobian_columns(dyn, kernel):
    """(columns, what they differentiate) of a column kernel: the tangents of the Lagrangian
    graph (GraphJacobians.columns; "" for the docstring), or of the recursive programs when the
    model is a tree of joints and they take fewer operations both in the kernel's text (what
    LLVM compiles) and per call (column_operation_counts)."""
    columns = dyn.jac.columns(kernel)
    source = ""
    if dyn.recursive is not None:
        seeds = columns[0][1]
        recursive = dyn.recursive.columns(kernel, seeds, dyn.ops.symbols(dyn.aux["w"]))
        graph = dyn.ops.graph
        ours, theirs = column_operation_counts(graph, recursive), column_operation_counts(graph, columns)
        if ours[0] < theirs[0] and ours[1] <= theirs[1]:
            columns, source = recursive, RECURSIVE_SOURCES[kernel]
    return columns, source


def recursive_mass_kernels(dyn) -> dict:
    """mass_matrix and dynamics of a tree of joints with H as a loop over its columns
    (recursive_mass_specs), each where that takes fewer operations than the graph's H (and rhs)
    written out, both in the kernel's text and per call (column_operation_counts); {} for
    other models."""
    if "_recursive_mass_kernels" not in dyn.__dict__:       # kernel_table is built several times
        dyn.__dict__["_recursive_mass_kernels"] = {
            name: build for name, (build, compiled, per_call, written_out) in recursive_mass_specs(dyn).items()
            if compiled < written_out and per_call <= written_out}
    return dyn.__dict__["_recursive_mass_kernels"]


def recursive_mass_specs(dyn) -> dict:
    """{name: (KernelSpec builder, operations in its text, per call, of the written-out kernel)}
    for mass_matrix and dynamics of a tree of joints (dyn.recursive; {} otherwise): column k
    of H is RNEA at rest with qdd = e_k and no model forces (RecursiveDynamics.mass_times),
    dynamics' rhs = -tau(q, qd, 0) by RNEA."""
    rec, o = dyn.recursive, dyn.ops
    if rec is None or dyn.mass_is_constant:
        return {}
    graph, n = o.graph, dyn.n
    seeds = [se.Symbol(f"{SEED_PREFIX}{i}") for i in range(n)]
    H_columns = [("H", seeds, rec.mass_times(seeds))]
    dynamics_columns = H_columns + [("rhs", [], [graph.node(-x) for x in rec.inverse_dynamics([0] * n)])]
    # the loop gives every entry of H; the upper triangle is copied from the lower, which
    # cholesky_inplace reads, so that H is exactly symmetric as the written-out one is
    mirror = [f"for i in range({n}):", f"    for j in range(i + 1, {n}):", "        H[i, j] = H[j, i]"]
    H_doc = "column by column (column k: RNEA at rest with qdd = e_k, no model forces)"

    def mass_matrix():
        return KernelSpec("mass_matrix", ["q", "t", "p"], out_args=["H"], columns=H_columns,
                          epilogue=mirror, doc=f"H(q, t) (n, n), the generalized inertia, {H_doc}")

    def dynamics():
        return KernelSpec("dynamics", ["q", "qd", "t", "p"], out_args=["H", "rhs"],
                          columns=dynamics_columns, epilogue=mirror,
                          doc=f"H(q) (n, n) and rhs = Q - h - g (n,), so that H qddot = rhs: H "
                              f"{H_doc}, rhs = -tau(q, qd, 0) by RNEA")
    H = list(dyn.native["H"])
    return {"mass_matrix": (mass_matrix, *column_operation_counts(graph, H_columns), operation_count(graph, H)),
            "dynamics": (dynamics, *column_operation_counts(graph, dynamics_columns),
                         operation_count(graph, H + list(dyn.native["rhs"])))}


def io_kernels(dyn) -> dict:
    """The kernels of a model with inputs (d rhs/du, for lagrange_gen.linearize) or outputs
    (their values and Jacobians); {} for a model without either."""
    model, o, table = dyn.model, dyn.ops, {}
    inputs = live_inputs(dyn)
    if inputs:
        u = o.symbols(inputs)
        table["input_jacobian"] = lambda: KernelSpec(
            "input_jacobian", ["q", "qd", "t", "p"], [Output("Ju", o.jacobian(list(dyn.native["rhs"]), u))],
            doc="d rhs/du (n, n_inputs), u the INPUTS (the trailing entries of p)")
    if model.outputs:
        y = [o.native(e) for e in output_functions(dyn)]
        table["outputs"] = lambda: KernelSpec(
            "outputs", ["q", "qd", "t", "p"], [Output("out", o.column(y))],
            doc="outputs y (n_outputs,) in OUTPUTS order")
        table["output_jacobian"] = lambda: KernelSpec(
            "output_jacobian", ["q", "qd", "t", "p"],
            [Output("Cq", o.jacobian(y, dyn.jac._q)), Output("Cqd", o.jacobian(y, dyn.jac._qd)),
             Output("Du", o.jacobian(y, o.symbols(inputs)) if inputs else o.zeros(len(y), 0))],
            doc="dy/dq, dy/dqd (n_outputs, n) and dy/du (n_outputs, n_inputs)")
    return table


def live_inputs(dyn) -> list:
    """The model's inputs that are still parameters (a frozen input is a constant)."""
    return [u for u in dyn.model.inputs if u.name not in dyn.frozen]


def output_functions(dyn) -> list:
    """The model's outputs y(q, qd, t) (sympy) in OUTPUTS order, frozen parameters substituted."""
    out = []
    for expr in dyn.model.outputs.values():
        frozen = {s: sp.Float(dyn.frozen[s.name]) for s in expr.free_symbols
                  if isinstance(s, Parameter) and s.name in dyn.frozen}
        out.append(expr.xreplace(frozen) if frozen else expr)
    return out


def _column(exprs):
    """A column Matrix (len, 1), also for no entries (sp.Matrix([]) is 0 x 0)."""
    return sp.Matrix(len(exprs), 1, list(exprs))


def event_functions(dyn) -> list:
    """The model's event functions g_k(q, qd, t) (sympy), frozen parameters substituted (the
    derivation's freeze_model substitutes the expressions it derives; events are only printed)."""
    out = []
    for event in dyn.model.events:
        frozen = {s: sp.Float(dyn.frozen[s.name]) for s in event.expr.free_symbols
                  if isinstance(s, Parameter) and s.name in dyn.frozen}
        out.append(event.expr.xreplace(frozen) if frozen else event.expr)
    return out


def default_kernels(dyn) -> tuple:
    """The kernels of a module generated for every method: all of kernel_table except ``rhs``,
    which is added only for a constant mass matrix (forward dynamics with a pre-factored H), and
    the parameter derivatives (SENSITIVITY_KERNELS), added only when sensitivities are asked."""
    return tuple(k for k in kernel_table(dyn) if (k != "rhs" or dyn.mass_is_constant)
                 and k not in SENSITIVITY_KERNELS)
