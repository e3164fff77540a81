"""Expression graphs: named intermediate values and derivatives through them, never expanded.

A spatial chain's kinetic energy written out is a tree whose size triples with every body (each
rotation matrix entry is a sum of three products of the previous body's entries); derived twice
for H and h and again for Newton's Jacobians, nothing finishes past a few bodies. The same
energy as a *graph* is small: each body adds a fixed number of nodes (its rotation, position,
velocity and angular velocity entries, each defined from its parent's), so the graph grows
linearly with the number of bodies.

``Graph`` is a straight-line program: node symbols ``z_<k>`` in definition order, each defined
by a small symengine expression over the inputs (coordinates, velocities, parameters, t, kernel
input vectors) and earlier nodes. Identical definitions share one node (hash-consing). Every
derivative is taken through the graph by the chain rule on the nodes' local definitions, and its
results are nodes again:

* ``diff(expr, x)``: d expr / d x for one input x (forward mode; each node downstream of x gets
  one derivative node, made once per x and kept);
* ``tangent(expr, direction)``: the directional derivative sum_x d expr/dx * direction[x]
  (forward mode along a vector, e.g. d/dt = qd . d/dq), one pass for the whole direction;
* ``gradient(expr, xs)``: d expr / d x for every x in ``xs`` at once (reverse mode: the adjoint
  of each node is one sum over its users), the cost of one evaluation of expr.

So the kinetic energy's momentum p = dT/dqd and dT/dq cost one reverse pass, the mass matrix
H = dp/dqd n forward passes, the velocity terms h = dp/dq qd - dT/dq one tangent pass: sizes
linear (gradient, h) and quadratic (H, Jacobians) in the graph, where expanded trees grow
exponentially. ``expand`` substitutes definitions back (small graphs only: tests and sympy
output).
"""

from __future__ import annotations

import math

import symengine as se

#: Prefix of node symbols. Kernel placeholders are q_<i>, qd_<i>, p_<i>, t, w_<i>, lam_<i>,
#: we_<i> and CSE temporaries x<k>, so node names never collide with them in emitted code.
NODE_PREFIX = "z_"


def _is_atom(expr) -> bool:
    return expr.is_Number or expr.is_Symbol


class Graph:
    """A straight-line program of named intermediate values (module docstring).

    defs: {node symbol: definition}; order: node symbols in definition order (a definition uses
    inputs and earlier nodes only). Inputs are every symbol that is not a node.
    """

    def __init__(self):
        self.defs: dict = {}
        self.order: list = []
        self._intern: dict = {}
        self._deps: dict = {}
        # per node, kept because every pass over the graph (reachability, the n forward passes
        # of a Jacobian, the emitted text) reads them again: its position in ``order``, the
        # nodes its definition uses, and its local partial derivatives {symbol: d def/d symbol}
        self._index: dict = {}
        self._uses: dict = {}
        self._partials: dict = {}
        self._forward: dict = {}        # direction key -> [{node: derivative}, nodes processed]

    def __len__(self):
        return len(self.order)

    def is_node(self, sym) -> bool:
        return sym in self.defs

    # -- building -------------------------------------------------------------------------
    def node(self, expr):
        """``expr`` as a node symbol (a new one, or the node with the same definition); numbers
        and symbols are returned as they are."""
        expr = se.sympify(expr)
        if _is_atom(expr):
            return expr
        found = self._intern.get(expr)
        if found is not None:
            return found
        # sorted: node numbers (and so the generated text) must not follow set order
        calls = {f: self.node(f) for f in sorted(expr.atoms(se.Function), key=str) if f != expr}
        if calls:                       # each sin(q_3) computed once, wherever it is used
            expr = expr.xreplace(calls)
            found = self._intern.get(expr)
            if found is not None:
                return found
        sym = se.Symbol(f"{NODE_PREFIX}{len(self.order)}")
        free = expr.free_symbols
        self._index[sym] = len(self.order)
        self.defs[sym] = expr
        self.order.append(sym)
        self._intern[expr] = sym
        self._uses[sym] = tuple(u for u in free if u in self.defs and u != sym)
        self._deps[sym] = self._inputs_of_symbols(free)
        return sym

    def inputs_of(self, expr) -> frozenset:
        """The input symbols ``expr`` depends on, through its nodes."""
        deps = self._deps.get(expr)
        if deps is not None:            # a node
            return deps
        return self._inputs_of_symbols(expr.free_symbols)

    def _inputs_of_symbols(self, symbols) -> frozenset:
        out = set()
        for s in symbols:
            deps = self._deps.get(s)
            if deps is None:
                out.add(s)
            else:
                out |= deps
        return frozenset(out)

    def _local_partials(self, sym) -> dict:
        """{symbol: d definition / d symbol} of a node's definition, non-zero ones only."""
        partials = self._partials.get(sym)
        if partials is None:
            definition = self.defs[sym]
            partials = {}
            for s in definition.free_symbols:
                local = definition.diff(s)
                if local != 0:
                    partials[s] = local
            self._partials[sym] = partials
        return partials

    # -- derivatives ----------------------------------------------------------------------
    def _chain(self, expr, seeds, derivatives, partials=None):
        """sum over the free symbols s of expr of d expr/ds * ds/dx, where ds/dx is seeds[s] for
        an input and derivatives[s] for a node (absent: zero); ``partials``: expr's
        {s: d expr/ds} when known (a node's, _local_partials)."""
        terms = []
        if partials is not None:
            for s, local in partials.items():
                ds = derivatives.get(s) if s in self.defs else seeds.get(s)
                if ds is not None and ds != 0:
                    terms.append(local * ds)
            return se.Add(*terms) if terms else se.Integer(0)
        for s in expr.free_symbols:
            ds = derivatives.get(s) if s in self.defs else seeds.get(s)
            if ds is None or ds == 0:
                continue
            local = expr.diff(s)
            if local != 0:
                terms.append(local * ds)
        return se.Add(*terms) if terms else se.Integer(0)

    def _forward_pass(self, seeds: dict, nodes):
        """{node: derivative node} along ``seeds`` {input: derivative} for the ``nodes`` (in
        definition order, with everything they use) that depend on a seeded input. Kept per
        direction: nodes already processed are not processed again. Only the nodes an
        expression uses are differentiated, never the whole graph (which holds the
        derivative nodes of earlier passes too)."""
        key = tuple(sorted((str(k), str(v)) for k, v in seeds.items()))
        state = self._forward.get(key)
        if state is None:
            state = self._forward[key] = ({}, set())
        derivatives, done = state
        seeded = frozenset(s for s, v in seeds.items() if v != 0)
        for sym in nodes:
            if sym in done:
                continue
            done.add(sym)
            if self._deps[sym] & seeded:
                value = self.node(self._chain(self.defs[sym], seeds, derivatives,
                                              self._local_partials(sym)))
                if value != 0:
                    derivatives[sym] = value
        return derivatives

    def tangent(self, expr, direction: dict):
        """The directional derivative sum_x d expr/dx * direction[x] ({input: expression})."""
        return self.tangents([expr], direction)[0]

    def tangents(self, exprs, direction: dict, nodes=None):
        """[tangent(e, direction) for e in exprs] in one pass (``nodes``: _reachable(exprs),
        when the caller already has it)."""
        exprs = [se.sympify(e) for e in exprs]
        seeds = {se.sympify(k): se.sympify(v) for k, v in direction.items()}
        derivatives = self._forward_pass(seeds, self._reachable(*exprs) if nodes is None else nodes)
        return [self._chain(e, seeds, derivatives) for e in exprs]

    def diff(self, expr, x):
        """d expr / d x for one input symbol x."""
        return self.tangent(expr, {x: 1})

    def jacobian(self, exprs, xs):
        """[[d e / d x for x in xs] for e in exprs] (row-major list of lists)."""
        exprs = [se.sympify(e) for e in exprs]
        nodes = self._reachable(*exprs)
        columns = [self.tangents(exprs, {x: 1}, nodes) for x in xs]
        return [[columns[k][i] for k in range(len(xs))] for i in range(len(exprs))]

    def gradient(self, expr, xs):
        """[d expr / d x for x in xs] by reverse accumulation (one pass over the nodes expr
        uses, whatever len(xs))."""
        expr = se.sympify(expr)
        adjoint: dict = {}

        def add(sym, contribution):
            if contribution != 0:
                adjoint.setdefault(sym, []).append(contribution)

        for s in expr.free_symbols:
            add(s, expr.diff(s))
        for sym in reversed(self._reachable(expr)):
            parts = adjoint.pop(sym, None)
            if not parts:
                continue
            bar = self.node(se.Add(*parts))
            for s, local in self._local_partials(sym).items():
                add(s, bar * local)
        return [self.node(se.Add(*adjoint[x])) if x in adjoint else se.Integer(0)
                for x in (se.sympify(x) for x in xs)]

    def _reachable(self, *exprs):
        """The nodes ``exprs`` use (directly or through other nodes), in definition order."""
        uses = self._uses
        seen, stack = set(), [s for e in exprs for s in e.free_symbols if s in uses]
        while stack:
            s = stack.pop()
            if s in seen:
                continue
            seen.add(s)
            stack.extend(u for u in uses[s] if u not in seen)
        return sorted(seen, key=self._index.__getitem__)

    def used_nodes(self, exprs):
        """[(node, definition)] that evaluating ``exprs`` needs, in evaluation order."""
        return [(s, self.defs[s]) for s in self._reachable(*[se.sympify(e) for e in exprs])]

    # -- leaving the graph ----------------------------------------------------------------
    def expand(self, expr):
        """``expr`` with every node replaced by its definition, recursively (exponential in
        general: for small graphs, tests and readable output only)."""
        expr = se.sympify(expr)
        nodes = self._reachable(expr)
        if not nodes:
            return expr
        values = {}
        for s in nodes:
            values[s] = self.defs[s].xreplace({u: values[u] for u in self.defs[s].free_symbols if u in values})
        return expr.xreplace({s: values[s] for s in expr.free_symbols if s in values})

    def evaluator(self, inputs, exprs):
        """f(values (len(inputs),)) -> list of floats (len(exprs),): the nodes ``exprs`` need
        evaluated in order by plain Python (numeric checks at generation time)."""
        inputs = [se.sympify(s) for s in inputs]
        exprs = [se.sympify(e) for e in exprs]
        rename = {s: se.Symbol(f"a_{i}") for i, s in enumerate(inputs)}
        lines = ["def f(a):"] + [f"    a_{i} = a[{i}]" for i in range(len(inputs))]
        for sym, definition in self.used_nodes(exprs):
            lines.append(f"    {sym} = {definition.xreplace(rename)}")
        lines.append(f"    return [{', '.join(str(e.xreplace(rename)) for e in exprs)}]")
        namespace = dict(_NUMERIC)
        exec(compile("\n".join(lines), "<lagrange_gen graph>", "exec"), namespace)  # noqa: S102  our own text
        return namespace["f"]


#: Names symengine prints, as Python callables (numeric checks only).
_NUMERIC = {name: getattr(math, name) for name in
            ("sin", "cos", "tan", "asin", "acos", "atan", "sinh", "cosh", "tanh", "asinh", "acosh",
             "atanh", "exp", "log", "sqrt", "erf", "erfc", "gamma", "pi")}
_NUMERIC.update({"atan2": math.atan2, "Abs": abs, "E": math.e,
                 "sign": lambda x: float((x > 0) - (x < 0)),
                 "cot": lambda x: 1.0 / math.tan(x), "sec": lambda x: 1.0 / math.cos(x),
                 "csc": lambda x: 1.0 / math.sin(x)})
