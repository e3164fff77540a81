"""Recursive rigid-body algorithms as expression-graph programs, specialized to the model's constants.

For a kinetic energy built from bodies that form a tree of joints (model/joint_form.py), the
inverse dynamics (RNEA) and the forward dynamics (ABA, Featherstone's articulated-body
algorithm) take O(n) operations where H from n tangents of the momentum and its Cholesky
factorization take O(n^2) and more. Each algorithm is written here once, over spatial vectors
whose entries are graph nodes (derive/graph.py): the joint axes, offsets and inertias are
numbers, so the products with their zeros and ones vanish as the nodes are made, and the
emitter writes the result like any other graph kernel.

Only T goes through the tree. The potential, dissipation, forces and inputs enter as the
generalized force tau_model = Q - dV/dq (the graph's own g and Q), so gravity needs no special
case. Conventions: spatial vectors (angular; linear) in a link's frame at its origin; a link's
transform from its parent is [x]_link = E [x]_parent with origin r (joint_form.Link).

``recursive_dynamics`` checks, at random states, the tree's kinetic energy, its inverse dynamics
and its forward dynamics against the graph's T, H qdd + h + g - Q and H^-1 rhs; any difference
and the module is not used (the H + Cholesky kernels stay).
"""

from __future__ import annotations

import weakref

import numpy as np
import symengine as se
import sympy as sp

from ..model.symbols import Parameter, t

__all__ = ["RecursiveDynamics", "recursive_dynamics", "operation_count", "column_operation_counts"]


def _count(e):
    """Arithmetic operations and function calls in one native expression."""
    if e.is_Number or e.is_Symbol:
        return 0
    own = len(e.args) - 1 if type(e).__name__ in ("Add", "Mul") else 1
    return own + sum(_count(a) for a in e.args)


#: {graph: {node: _count of its definition}}: the generator weighs several programs over the
#: same nodes (recursive or graph, per kernel), and a definition never changes.
_NODE_COUNTS = weakref.WeakKeyDictionary()


def _node_count(graph, node, definition):
    counts = _NODE_COUNTS.get(graph)
    if counts is None:
        counts = _NODE_COUNTS[graph] = {}
    found = counts.get(node)
    if found is None:
        found = counts[node] = _count(definition)
    return found


def operation_count(graph, exprs):
    """Arithmetic operations and function calls to evaluate ``exprs`` (native) with the graph
    nodes they use: what numba's compile time and the run time follow."""
    return (sum(_node_count(graph, s, d) for s, d in graph.used_nodes(exprs))
            + sum(_count(se.sympify(e)) for e in exprs))


def column_operation_counts(graph, columns):
    """(compiled, per call) operations of a kernel written as loops over columns
    (codegen.emit.render_column_kernel; columns [(output name, seeds, column)]): the nodes that
    do not depend on the seeds are evaluated once, the others once per column. compiled: the
    operations in the kernel's text (what LLVM's compile time follows), the seed-free nodes
    plus one pass of each loop; per call: the seed-free nodes plus every pass."""
    seeds = {s for _, column_seeds, _ in columns for s in column_seeds}
    every = [e for _, _, column in columns for e in column]
    outside = sum(_node_count(graph, s, d) for s, d in graph.used_nodes(every)
                  if not graph.inputs_of(s) & seeds)
    compiled, per_call = outside, outside
    for _, column_seeds, column in columns:
        inside = sum(_node_count(graph, s, d) for s, d in graph.used_nodes(column)
                     if graph.inputs_of(s) & seeds)
        inside += sum(_count(se.sympify(e)) for e in column)
        compiled, per_call = compiled + inside, per_call + len(column_seeds) * inside
    return compiled, per_call


def _cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


class RecursiveDynamics:
    """The tree's recursions over the graph of ``o`` (GraphOps); q, qd native symbols (n,),
    tau_model (n,) native: Q - g, the generalized forces besides inertia."""

    def __init__(self, links, o, q, qd, tau_model, frozen):
        self.graph, self.o = o.graph, o
        self.n, self.q, self.qd, self.tau_model = len(q), list(q), list(qd), list(tau_model)
        names = {str(s): i for i, s in enumerate(q)}
        freeze = {}
        self.links = []
        for link in links:
            for e in (link.S, link.E, link.r, link.com, link.inertia, link.mass):
                freeze.update({p: sp.Float(frozen[p.name]) for p in sp.sympify(e).free_symbols
                               if isinstance(p, Parameter) and p.name in frozen})

            def native(matrix):
                return [[o.native(matrix[i, j].xreplace(freeze)) for j in range(matrix.cols)] for i in range(matrix.rows)]
            cols = [list(col) for col in zip(*native(link.S))] if link.S.cols else []
            E, Ic = native(link.E), native(link.inertia)
            r, c = [row[0] for row in native(link.r)], [row[0] for row in native(link.com)]
            m = o.native(sp.sympify(link.mass).xreplace(freeze))
            cx = [[0, -c[2], c[1]], [c[2], 0, -c[0]], [-c[1], c[0], 0]]
            A = [[Ic[i][j] + m * sum(cx[i][l] * cx[j][l] for l in range(3)) for j in range(3)] for i in range(3)]
            B = [[m * cx[i][j] for j in range(3)] for i in range(3)]
            inertia = [A[i] + B[i] for i in range(3)] + [[B[j][i] for j in range(3)] + [m if j == i else 0 for j in range(3)]
                                                          for i in range(3)]
            S_dot = [[sum(s.diff(x) * o.native(sp.Symbol(str(x) + "_dot")) for x in s.free_symbols if str(x) in names)
                      for s in col] for col in cols]
            self.links.append(dict(parent=link.parent, joint=[names[str(x)] for x in link.coords], S=cols,
                                   S_dot=S_dot, E=E, r=r, inertia=inertia))

    # -- spatial algebra on lists of graph nodes -------------------------------------------
    def _nodes(self, exprs):
        return [self.graph.node(e) for e in exprs]

    def _to_child(self, link, m):
        """X m: a motion vector of the parent in the link's coordinates."""
        E, r = link["E"], link["r"]
        w, v = m[:3], [a + b for a, b in zip(m[3:], _cross(m[:3], r))]
        return self._nodes([sum(E[i][j] * w[j] for j in range(3)) for i in range(3)] +
                           [sum(E[i][j] * v[j] for j in range(3)) for i in range(3)])

    def _to_parent(self, link, f):
        """X^T f: a force of the link in the parent's coordinates."""
        E, r = link["E"], link["r"]
        fp = self._nodes([sum(E[j][i] * f[3 + j] for j in range(3)) for i in range(3)])
        n = [sum(E[j][i] * f[j] for j in range(3)) for i in range(3)]
        return self._nodes([a + b for a, b in zip(n, _cross(r, fp))] + fp)

    def _congruence(self, link, M):
        """X^T M X (6, 6) for a symmetric M (6, 6) in the link's coordinates: the parent's view."""
        E, r = link["E"], link["r"]

        def rotated(block, symmetric):                       # E^T block E
            half = [[self.graph.node(sum(block[i][l] * E[l][j] for l in range(3))) for j in range(3)] for i in range(3)]
            out = [[None] * 3 for _ in range(3)]
            for i in range(3):
                for j in range(i if symmetric else 0, 3):
                    out[i][j] = self.graph.node(sum(E[l][i] * half[l][j] for l in range(3)))
                    if symmetric:
                        out[j][i] = out[i][j]
            return out
        A = rotated([row[:3] for row in M[:3]], True)
        B = rotated([row[3:] for row in M[:3]], False)
        C = rotated([row[3:] for row in M[3:]], True)
        rx = [[0, -r[2], r[1]], [r[2], 0, -r[0]], [-r[1], r[0], 0]]

        def mul(P, Q):
            return [[self.graph.node(sum(P[i][l] * Q[l][j] for l in range(3))) for j in range(3)] for i in range(3)]
        K, rC = mul(B, rx), mul(rx, C)
        rCr = mul(rC, rx)
        top = self._symmetric(3, lambda i, j: A[i][j] - K[i][j] - K[j][i] - rCr[i][j])
        right = [[self.graph.node(B[i][j] + rC[i][j]) for j in range(3)] for i in range(3)]
        return [top[i] + right[i] for i in range(3)] + [[right[j][i] for j in range(3)] + C[i] for i in range(3)]

    def _symmetric(self, size, entry):
        """The symmetric (size, size) matrix of nodes entry(i, j), formed for j >= i only: the
        articulated inertias are symmetric, and a product computed twice in a different order
        would be two nodes."""
        out = [[None] * size for _ in range(size)]
        for i in range(size):
            for j in range(i, size):
                out[i][j] = out[j][i] = self.graph.node(entry(i, j))
        return out

    def _times(self, M, x):
        return self._nodes([sum(M[i][j] * x[j] for j in range(6)) for i in range(6)])

    def _cross_motion(self, v, m):
        w, v0 = v[:3], v[3:]
        return self._nodes(_cross(w, m[:3]) + [a + b for a, b in zip(_cross(w, m[3:]), _cross(v0, m[:3]))])

    def _cross_force(self, v, f):
        w, v0 = v[:3], v[3:]
        return self._nodes([a + b for a, b in zip(_cross(w, f[:3]), _cross(v0, f[3:]))] + _cross(w, f[3:]))

    def _velocities(self, qd=None):
        """[(v, c)] per link: spatial velocity and velocity-product acceleration c = S' qd + v x vJ
        for the joint velocities ``qd`` (n native expressions; None: the model's qd symbols)."""
        qd = self.qd if qd is None else qd
        out = []
        for link in self.links:
            rates = [qd[j] for j in link["joint"]]
            vJ = self._nodes([sum(col[i] * x for col, x in zip(link["S"], rates)) for i in range(6)])
            parent = [0] * 6 if link["parent"] < 0 else self._to_child(link, out[link["parent"]][0])
            v = self._nodes([a + b for a, b in zip(parent, vJ)])
            S_dot_qd = [sum(col[i] * x for col, x in zip(link["S_dot"], rates)) for i in range(6)]
            c = self._nodes([a + b for a, b in zip(S_dot_qd, self._cross_motion(v, vJ))])
            out.append((v, c))
        return out

    # -- the algorithms ----------------------------------------------------------------------
    def kinetic_energy(self):
        """T of the tree, sum 1/2 v . I v (checked against the model's T)."""
        total = 0
        for link, (v, _) in zip(self.links, self._velocities()):
            total += sum(a * b for a, b in zip(v, self._times(link["inertia"], v))) / 2
        return self.graph.node(total)

    def inverse_dynamics(self, qdd, qd=None, forces=None):
        """tau (n,) = H qdd + h + g - Q by RNEA (qdd: n native expressions, zeros for h + g - Q).
        qd (n,): the joint velocities (None: the model's qd symbols; zeros drop h); forces (n,):
        the generalized forces besides inertia (None: tau_model = Q - g; zeros give H qdd + h)."""
        kinematics = self._velocities(qd)
        tau_model = self.tau_model if forces is None else list(forces)
        accelerations, forces = [], []
        for link, (v, c) in zip(self.links, kinematics):
            parent = [0] * 6 if link["parent"] < 0 else self._to_child(link, accelerations[link["parent"]])
            joint = [sum(col[i] * qdd[j] for col, j in zip(link["S"], link["joint"])) for i in range(6)]
            a = self._nodes([p + s + x for p, s, x in zip(parent, joint, c)])
            accelerations.append(a)
            forces.append(self._nodes([x + y for x, y in zip(
                self._times(link["inertia"], a), self._cross_force(v, self._times(link["inertia"], v)))]))
        tau = [0] * self.n
        for i in reversed(range(len(self.links))):
            link = self.links[i]
            for col, j in zip(link["S"], link["joint"]):
                tau[j] = self.graph.node(sum(s * f for s, f in zip(col, forces[i])))
            if link["parent"] >= 0:
                up = self._to_parent(link, forces[i])
                forces[link["parent"]] = self._nodes([a + b for a, b in zip(forces[link["parent"]], up)])
        return [self.graph.node(x - y) for x, y in zip(tau, tau_model)]

    def mass_times(self, w):
        """H(q) w (n,) for a vector w (n native expressions): RNEA at rest (qd = 0) with qdd = w
        and no forces besides inertia, so that only the inertia term is left."""
        zeros = [0] * self.n
        return self.inverse_dynamics(w, qd=zeros, forces=zeros)

    def momentum_rate(self):
        """dp/dt at qdd = 0, i.e. dT/dq - g + Q (n,): p = H qd, so dp/dt = Hdot qd + H qdd and
        Lagrange's equations give dT/dq - g + Q = Hdot qd - tau(q, qd, 0); Hdot qd is the
        tangent of H(q) w along qd in q, at w = qd."""
        Hw = self.mass_times(self.qd)
        Hdot_qd = self.graph.tangents(Hw, dict(zip(self.q, self.qd)))
        bias = self.inverse_dynamics([0] * self.n)
        return [self.graph.node(a - b) for a, b in zip(Hdot_qd, bias)]

    def columns(self, kernel, seeds, w):
        """[(output name, seeds, column)] of a Newton Jacobian kernel (the names and outputs of
        derive.structured.GraphJacobians.columns) as tangents of the recursive programs along
        one coordinate or velocity at a time (``seeds``: n seed symbols; w: the n native
        symbols of the kernel's input vector w):

            rhs_jacobian             rhs = Q - h - g = -tau(q, qd, 0), the bias RNEA
            mass_matvec_dq           H w = RNEA at qd = 0, qdd = w, no model forces
            momentum_rate_jacobian   dT/dq - g + Q = Hdot qd - tau(q, qd, 0) (momentum_rate)
        """
        def along(exprs, xs):
            return self.graph.tangents(exprs, dict(zip(xs, seeds)))

        if kernel == "mass_matvec_dq":
            return [("out_mat", seeds, along(self.mass_times(w), self.q))]
        if kernel == "rhs_jacobian":
            values = [self.graph.node(-x) for x in self.inverse_dynamics([0] * self.n)]
        elif kernel == "momentum_rate_jacobian":
            values = self.momentum_rate()
        else:
            raise KeyError(kernel)
        return [("Jq", seeds, along(values, self.q)), ("Jqd", seeds, along(values, self.qd))]

    def forward_dynamics(self, tau_extra=None):
        """(qdd (n,), pivots) by ABA for the generalized forces tau_model (+ tau_extra, n native
        symbols); pivots: the joints' D = S^T I^A S (each must be > 0)."""
        tau = list(self.tau_model) if tau_extra is None else [self.graph.node(a + b) for a, b in zip(self.tau_model, tau_extra)]
        kinematics = self._velocities()
        IA = [[row[:] for row in link["inertia"]] for link in self.links]
        pA = [self._cross_force(v, self._times(link["inertia"], v)) for link, (v, _) in zip(self.links, kinematics)]
        solved = {}
        for i in reversed(range(len(self.links))):
            link, (_, c) = self.links[i], kinematics[i]
            Ia, pa = IA[i], pA[i]
            if len(link["joint"]) > 1:
                solved[i] = self._several(link, IA[i], pA[i], tau)
                if link["parent"] >= 0:
                    Ia, pa = self._articulated_several(IA[i], pA[i], c, *solved[i][:4])
            elif link["joint"]:
                (S,), j = link["S"], link["joint"][0]
                U = self._times(IA[i], S)
                D = self.graph.node(sum(s * u for s, u in zip(S, U)))
                D_inv = self.graph.node(1 / D)
                u = self.graph.node(tau[j] - sum(s * p for s, p in zip(S, pA[i])))
                solved[i] = (U, D, D_inv, u, j)
                if link["parent"] >= 0:
                    W = self._nodes([x * D_inv for x in U])
                    Ia = self._symmetric(6, lambda r, s: IA[i][r][s] - U[r] * W[s])
                    pa = self._nodes([p + x + w * u for p, x, w in zip(pA[i], self._times(Ia, c), W)])
            elif link["parent"] >= 0:
                pa = self._nodes([p + x for p, x in zip(pA[i], self._times(Ia, c))])
            if link["parent"] >= 0:
                parent = link["parent"]
                extra = self._congruence(link, Ia)
                IA[parent] = self._symmetric(6, lambda r, s, P=IA[parent]: P[r][s] + extra[r][s])
                pA[parent] = self._nodes([a + b for a, b in zip(pA[parent], self._to_parent(link, pa))])
        qdd, pivots, accelerations = [0] * self.n, [], []
        for i, link in enumerate(self.links):
            c = kinematics[i][1]
            parent = [0] * 6 if link["parent"] < 0 else self._to_child(link, accelerations[link["parent"]])
            a = self._nodes([x + y for x, y in zip(parent, c)])
            if i in solved and len(link["joint"]) > 1:
                U, _, D_inv, u, joints, d = solved[i]
                rest = [self.graph.node(x - sum(y * z for y, z in zip(col, a))) for x, col in zip(u, U)]
                for r, j in enumerate(joints):
                    qdd[j] = self.graph.node(sum(D_inv[r][s] * rest[s] for s in range(len(joints))))
                a = self._nodes([x + sum(S[k] * qdd[j] for S, j in zip(link["S"], joints)) for k, x in enumerate(a)])
                pivots += d
            elif i in solved:
                U, D, D_inv, u, j = solved[i]
                qdd[j] = self.graph.node(D_inv * (u - sum(x * y for x, y in zip(U, a))))
                a = self._nodes([x + s * qdd[j] for x, s in zip(a, link["S"][0])])
                pivots.append(D)
            accelerations.append(a)
        return qdd, pivots


    def _several(self, link, IA, pA, tau):
        """(U (k columns of 6), D (k, k), D^-1 (k, k), u (k,), joints, LDL pivots (k,)) of a
        joint of k > 1 coordinates: U = I^A S, D = S^T U, u = tau_joint - S^T p^A."""
        cols, joints = link["S"], link["joint"]
        U = [self._times(IA, S) for S in cols]
        D = self._symmetric(len(cols), lambda r, s: sum(x * y for x, y in zip(cols[r], U[s])))
        u = [self.graph.node(tau[j] - sum(x * p for x, p in zip(S, pA))) for S, j in zip(cols, joints)]
        D_inv, d = self._spd_inverse(D)
        return U, D, D_inv, u, joints, d

    def _articulated_several(self, IA, pA, c, U, D, D_inv, u):
        """(I^a, p^a) handed to the parent by a joint of several coordinates: I^A - U D^-1 U^T,
        p^A + I^a c + U D^-1 u."""
        k = len(U)
        W = [[self.graph.node(sum(U[s][r] * D_inv[s][t] for s in range(k))) for r in range(6)] for t in range(k)]
        Ia = self._symmetric(6, lambda r, s: IA[r][s] - sum(W[t][r] * U[t][s] for t in range(k)))
        Du = [self.graph.node(sum(D_inv[t][s] * u[s] for s in range(k))) for t in range(k)]
        pa = self._nodes([p + x + sum(U[t][r] * Du[t] for t in range(k))
                          for r, (p, x) in enumerate(zip(pA, self._times(Ia, c)))])
        return Ia, pa

    def _spd_inverse(self, D):
        """(D^-1, pivots) of a symmetric positive definite (k, k) matrix of nodes by D = L diag(d)
        L^T written out (k <= 6: a joint's coordinates); the pivots d are positive exactly when
        D is positive definite."""
        k, node = len(D), self.graph.node
        L, d = [[0] * k for _ in range(k)], []
        for j in range(k):
            d.append(node(D[j][j] - sum(L[j][m] ** 2 * d[m] for m in range(j))))
            inv = node(1 / d[j])
            for i in range(j + 1, k):
                L[i][j] = node((D[i][j] - sum(L[i][m] * L[j][m] * d[m] for m in range(j))) * inv)
        columns = []
        for e in range(k):                         # D x = unit vector e: L y = e, L^T x = y / d
            y = []
            for i in range(k):
                y.append(node((1 if i == e else 0) - sum(L[i][m] * y[m] for m in range(i))))
            x = [0] * k
            for i in reversed(range(k)):
                x[i] = node(y[i] / d[i] - sum(L[m][i] * x[m] for m in range(i + 1, k)))
            columns.append(x)
        return [[columns[s][r] for s in range(k)] for r in range(k)], d


def recursive_dynamics(links, o, model, T, parts, qdd, frozen, samples=3):
    """RecursiveDynamics of the tree ``links`` (joint_form) over the graph of ``o``, or None when
    the tree does not reproduce the model's T, H qdd + h + g - Q and H^-1 rhs at ``samples``
    random states (T: the model's, native; parts: derive_lagrangian_graph's fields; qdd: n
    native symbols; frozen: {parameter name: value} folded into the links)."""
    q, qd = o.symbols(model.coords), o.symbols(model.velocities)
    if links is None or model.constraints or sorted(j for l in links for j in (str(x) for x in l.coords)) != sorted(map(str, q)):
        return None
    n = len(q)
    tau_model = [o.graph.node(a - b) for a, b in zip(parts["Q"].entries, parts["g"].entries)]
    try:
        rec = RecursiveDynamics(links, o, q, qd, tau_model, frozen)
        T_tree, tau = rec.kinetic_energy(), rec.inverse_dynamics(qdd)
        accelerations, pivots = rec.forward_dynamics()
    except (NotImplementedError, KeyError, ZeroDivisionError):
        return None
    graph = o.graph
    Hqdd = graph.tangents(parts["p"], dict(zip(qd, qdd)))
    reference = [graph.node(a - r) for a, r in zip(Hqdd, parts["rhs"].entries)]
    args = q + qd + list(qdd) + o.symbols(list(model.params) + [t])
    f = graph.evaluator(args, [T, T_tree, *tau, *reference, *accelerations])
    from .lagrangian import sample_values
    rng = np.random.default_rng(20261123)
    for _ in range(samples):
        state, rest = [*rng.uniform(-np.pi, np.pi, n), *rng.uniform(-1, 1, n)], [*sample_values(model), 0.5]
        values = np.asarray(f(state + list(rng.uniform(-1, 1, n)) + rest), dtype=float)
        T_m, T_r = values[:2]
        tau_r, tau_m, acc = values[2:2 + n], values[2 + n:2 + 2 * n], values[2 + 2 * n:]
        scale = 1.0 + abs(T_m) + np.abs(tau_m).max()
        # ABA solves the inverse dynamics (checked against the graph's) for zero joint force
        residual = np.asarray(f(state + list(acc) + rest), dtype=float)[2 + n:2 + 2 * n]
        if (abs(T_m - T_r) > 1e-9 * (1 + abs(T_m)) or np.abs(tau_r - tau_m).max() > 1e-9 * scale
                or np.abs(residual).max() > 1e-9 * (1.0 + np.abs(acc).max()) * scale):
            return None
    return rec
