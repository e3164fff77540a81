"""The derivation through an expression graph, for models whose energies keep their structure.

A model built from bodies (lagrange_gen.kinetic_energy, gravity_potential) gives T and V as
short sums over Intermediates: orientation, position and velocity entries, each defined from its
parent's (bodies.py). Their definitions become the nodes of a Graph (graph.py) and every
quantity the kernels need is formed through it, by the chain rule, never expanded:

    p = dT/dqd and dT/dq         one reverse pass over T
    H = dp/dqd                   n forward passes (upper triangle kept)
    h = (dp/dq) qd - dT/dq       one forward pass along qd (T is scleronomic here: dp/dt = 0)
    g = dV/dq, Q = F - dD/dqd    reverse passes
    rhs = Q - h - g, momentum_rate = dT/dq - g + Q

and the Newton Jacobians (d rhs/dq, d rhs/dqd, ..., d(H w)/dq with H w = the tangent of p along
w) by forward passes over those graphs: each costs a small multiple of the kernel it
differentiates. For a tree of joints codegen/spec.py takes them instead from the recursive
programs (derive/recursive.py RecursiveDynamics.columns) where those are shorter. The results are matrices of node symbols and short expressions over them; the
Dynamics record keeps the graph, and the emitter writes the nodes a kernel uses before its body.

The graph path applies to scleronomic T = 1/2 qd^T H(q) qd (no T1, T0 or explicit t in T).
Constraints and nonsmooth elements are derived as usual, from their own (expanded) expressions.
"""

from __future__ import annotations

import copy

import numpy as np
import symengine as se
import sympy as sp

from ..model.intermediates import Intermediate, expand_intermediates
from ..errors import ModelError
from ..model.symbols import Parameter, t
from .backend import Mat, Ops, backend_for
from .graph import Graph
from .jacobians import Jacobians


class GraphMat(Mat):
    """A Mat whose free_symbols are seen through the graph's nodes (the inputs they use)."""

    def __init__(self, rows, cols, entries, graph):
        super().__init__(rows, cols, entries)
        self.graph = graph

    @property
    def free_symbols(self):
        out = set()
        for e in self.entries:
            out |= self.graph.inputs_of(e)
        return out


class GraphOps(Ops):
    """Ops (symengine) whose matrices see through the graph and whose derivatives follow it."""

    def __init__(self, graph):
        super().__init__("symengine")
        self.graph = graph

    def matrix(self, rows, cols, entries):
        return GraphMat(rows, cols, [self.native(e) for e in entries], self.graph)

    def jacobian(self, exprs, variables):
        exprs, variables = list(exprs), list(variables)
        rows = self.graph.jacobian(exprs, variables)
        return self.matrix(len(exprs), len(variables), [e for row in rows for e in row])

    def to_sympy(self, obj, names):
        if isinstance(obj, Mat):
            return super().to_sympy(Mat(obj.rows, obj.cols, [self.graph.expand(e) for e in obj.entries]), names)
        return super().to_sympy(self.graph.expand(obj), names)

    def lambdify(self, args, exprs):
        f = self.graph.evaluator(args, list(exprs))
        return lambda values: np.asarray(f(list(values)), dtype=float).ravel()


def uses_graph(model) -> bool:
    """True when the model's expressions use Intermediates (bodies.py) and symengine can
    differentiate everything in them (backend.backend_for): the graph is symengine's."""
    used = getattr(model, "intermediates", ())
    if not used:
        return False
    exprs = [e for _, e in model._all_expressions()] + [s.definition for s in used]
    return backend_for(exprs) == "symengine"


def graph_model(model, expand_all=False):
    """A shallow copy of ``model`` whose constraints (holonomic and nonholonomic), element strains,
    events, contacts and outputs have
    their Intermediates expanded (those are derived or printed from their own expressions);
    with ``expand_all`` T, V, the dissipation and the forces too, and no Intermediates remain
    (the expression path of derive/lagrangian.py)."""
    out = copy.copy(model)
    if expand_all:
        out.T, out.V = expand_intermediates(model.T), expand_intermediates(model.V)
        out.dissipation = expand_intermediates(model.dissipation)
        out.forces = [expand_intermediates(f) for f in model.forces]
        out.intermediates = []
    out.constraints = [expand_intermediates(c) for c in model.constraints]
    out.nonholonomic = [expand_intermediates(c) for c in getattr(model, "nonholonomic", ())]
    out.elements = []
    for e in model.elements:
        e = copy.copy(e)
        e.strain = expand_intermediates(e.strain)
        out.elements.append(e)
    out.events = []
    for e in model.events:
        e = copy.copy(e)
        e.expr = expand_intermediates(e.expr)
        out.events.append(e)
    out.contacts = []
    for c in getattr(model, "contacts", ()):
        c = copy.copy(c)
        c.gap = expand_intermediates(c.gap)
        c.slips = tuple(expand_intermediates(u) for u in c.slips)
        out.contacts.append(c)
    out.outputs = {k: expand_intermediates(y) for k, y in model.outputs.items()}
    return out


def import_expressions(model, frozen, exprs):
    """(GraphOps, [native expression]) for sympy ``exprs`` over the model's Intermediates: each
    Intermediate becomes one node (identical definitions one node), the parameters named in
    ``frozen`` {name: value} substituted in every definition (freeze_model did the rest)."""
    frozen_sub = {}
    for s in model.intermediates:
        for p in s.definition.free_symbols:
            if isinstance(p, Parameter) and p.name in frozen:
                frozen_sub[p] = sp.Float(frozen[p.name])
    graph = Graph()
    o = GraphOps(graph)
    used = list(model.intermediates)
    # Intermediates print alike across trees (k1, k2, ... per call); plain names by position
    # keep them apart on the way to symengine, which knows symbols by name only.
    plain = {s: sp.Symbol(f"_intermediate_{i}") for i, s in enumerate(used)}
    node_of = {}
    for s in used:
        definition = s.definition.xreplace(frozen_sub).xreplace(plain) if frozen_sub else s.definition.xreplace(plain)
        native = o.native(definition)
        native = native.xreplace({o.native(plain[u]): node_of[o.native(plain[u])]
                                  for u in s.definition.atoms(Intermediate)})
        node_of[o.native(plain[s])] = graph.node(native)
    out = []
    for e in exprs:
        native = o.native(e.xreplace(plain))
        out.append(native.xreplace({k: v for k, v in node_of.items() if k in native.free_symbols}))
    return o, out


def derive_lagrangian_graph(model, o, T, V, D, forces, check_samples=8):
    """The fields of derive_lagrangian (same names and shapes) through the graph of ``o``:
    T, V, D native scalars and forces (n,) native, over nodes."""
    graph = o.graph
    q, qd = o.symbols(model.coords), o.symbols(model.velocities)
    time = o.native(t)
    n = len(q)
    zero = o.native(0)
    if time in graph.inputs_of(T):
        raise NotScleronomic("T depends on t")
    grad_T = graph.gradient(T, q + qd)
    dTdq, mom = grad_T[:n], grad_T[n:]
    dmom = graph.jacobian(mom, qd)
    upper = {(j, k): graph.node(dmom[j][k]) for k in range(n) for j in range(k + 1)}
    H = o.matrix(n, n, [upper[min(j, k), max(j, k)] for j in range(n) for k in range(n)])
    bad = sorted(str(s) for s in H.free_symbols if s in set(qd))
    if bad:
        raise ModelError(f"model {model.name}: T is not quadratic in the velocities "
                         f"(d2T/dqdot2 still depends on {', '.join(bad)})")
    along_qd = dict(zip(q, qd))
    h = [graph.node(d - dTdq[j]) for j, d in enumerate(graph.tangents(mom, along_qd))]
    g = graph.gradient(V, q)
    dD = graph.gradient(D, qd) if D != 0 else [zero] * n
    Q = [graph.node(f - d) for f, d in zip(forces, dD)]
    rhs = [graph.node(Q[j] - h[j] - g[j]) for j in range(n)]
    momentum_rate = [graph.node(dTdq[j] - g[j] + Q[j]) for j in range(n)]
    _check_quadratic(model, o, T, mom, H, check_samples)
    P = sum((qd[j] * Q[j] for j in range(n) if Q[j] != 0), zero)
    if time in graph.inputs_of(V):
        P = P + graph.diff(V, time)
    P = graph.node(P)
    power = [P, *graph.gradient(P, q + qd + [time])] if P != 0 else [zero] * (2 * n + 2)
    col = o.column
    return dict(H=H, h=col(h), g=col(g), Q=col(Q), rhs=col(rhs), dTdq=col(dTdq),
                momentum_rate=col(momentum_rate), E=graph.node(T + V), b=col([zero] * n),
                db=o.matrix(n, n, [zero] * (n * n)), power=col(power), p=mom, dH=None, Hdot=None, Ht=None)


class NotScleronomic(Exception):
    """T has terms the graph path does not treat (T1, T0, explicit t): derive expanded."""


def _check_quadratic(model, o, T, mom, H, samples):
    """At random states: T = 1/2 qd^T H qd with p = H qd (so T1 = T0 = 0), and H positive
    definite (the messages of derive/lagrangian.py)."""
    if samples <= 0:
        return
    from .lagrangian import sample_values, weakest_direction
    n = len(model.coords)
    args = o.symbols(list(model.coords) + list(model.velocities) + list(model.params) + [t])
    f = o.lambdify(args, [T, *mom, *H.entries])
    rng = np.random.default_rng(20261122)
    pvals = sample_values(model)
    for _ in range(samples):
        qs, vs, ts = rng.uniform(-np.pi, np.pi, n), rng.uniform(-1.0, 1.0, n), rng.uniform(0.0, 2.0)
        values = f([*qs, *vs, *pvals, ts])
        T_at, p_at, H_at = values[0], values[1:n + 1], values[n + 1:].reshape(n, n)
        scale = 1.0 + np.abs(H_at).max()
        if abs(T_at - vs @ H_at @ vs / 2) > 1e-9 * scale or np.abs(p_at - H_at @ vs).max() > 1e-9 * scale:
            raise NotScleronomic("T is not 1/2 qd^T H qd")
        try:
            np.linalg.cholesky(H_at)
        except np.linalg.LinAlgError:
            state = ", ".join(f"{c}={v:.3g}" for c, v in zip(model.coords, qs))
            eig, vectors = np.linalg.eigh(H_at)
            raise ModelError(f"model {model.name}: H = d2T/dqdot2 is not positive definite at {state} "
                             f"(smallest eigenvalue {eig[0]:.3g}; check the terms in "
                             f"{weakest_direction(model.coords, vectors[:, 0])})") from None


#: Names of the seed variables of a column loop (never a placeholder, temporary or node name).
SEED_PREFIX = "seed_"

#: The Jacobian kernels a graph model writes as loops over columns (GraphJacobians.columns).
COLUMN_KERNELS = ("rhs_jacobian", "momentum_rate_jacobian", "mass_matvec_dq")


class GraphJacobians(Jacobians):
    """The Newton Jacobians (jacobians.JACOBIANS) by forward passes through the graph."""

    def _graph_jacobian(self, field, variables):
        return self._o.jacobian(list(self._p[field]), variables)

    def _dQ_dqd(self):
        if "dQ_dqd" not in self._native:
            self._native["dQ_dqd"] = self._graph_jacobian("Q", self._qd)
        return self._native["dQ_dqd"]

    def _drhs_dq(self):
        return self._graph_jacobian("rhs", self._q)

    def _drhs_dqd(self):
        return self._graph_jacobian("rhs", self._qd)

    def _dmom_dq(self):
        return self._graph_jacobian("momentum_rate", self._q)

    def _dmom_dqd(self):
        return self._graph_jacobian("momentum_rate", self._qd)

    def _Hw(self):
        """H w (n,) as the tangent of p = H qd along w in the velocities."""
        graph = self._o.graph
        return [graph.node(e) for e in graph.tangents(self._p["p"], dict(zip(self._qd, self._w)))]

    def _dHw_dq(self):
        return self._o.jacobian(self._Hw(), self._q)

    def inverse_dynamics(self, qdd):
        """tau (n,) = H qdd + h + g - Q for accelerations ``qdd`` (n symbols): the tangent of
        p = H qd along qdd minus rhs, one pass over the graph (no H formed)."""
        graph = self._o.graph
        Hqdd = graph.tangents(self._p["p"], dict(zip(self._qd, qdd)))
        return [graph.node(a - r) for a, r in zip(Hqdd, self._p["rhs"])]

    def columns(self, kernel):
        """[(output name, seeds, column)] of a Jacobian kernel written as a loop over its columns
        (codegen.emit.render_column_kernel): column k of the output is ``column`` (n
        expressions) with seeds[i] = 1 for i == k and 0 otherwise, the tangent of the
        differentiated vector along one coordinate (or velocity). The code holds one tangent
        pass instead of n: its size is a small multiple of the kernel it differentiates, where
        the written-out Jacobian is n times that."""
        graph = self._o.graph
        seeds = [se.Symbol(f"{SEED_PREFIX}{i}") for i in range(len(self._q))]

        def along(exprs, xs):
            return graph.tangents(exprs, dict(zip(xs, seeds)))

        if kernel == "mass_matvec_dq":
            return [("out_mat", seeds, along(self._Hw(), self._q))]
        field = {"rhs_jacobian": "rhs", "momentum_rate_jacobian": "momentum_rate"}[kernel]
        values = list(self._p[field])
        return [("Jq", seeds, along(values, self._q)), ("Jqd", seeds, along(values, self._qd))]
