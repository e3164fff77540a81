"""Derivatives through an expression graph (derive/graph.py) against symengine's own derivative of
the same expression written out, on random graphs drawn from the grammar users write: sums,
products, divisions, negative and fractional powers, exp, log, sqrt, sin, cos, tan, tanh, atan2.

Each random graph is a chain of nodes, each defined from inputs and earlier nodes, so the
written-out expression nests the definitions (what a kinematic tree does). Values are compared
at a random point where every function is defined (positive arguments for log and fractional
powers)."""

import math

import numpy as np
import pytest
import symengine as se
from hypothesis import given, settings
from hypothesis import strategies as st

from lagrange_gen.derive.graph import Graph

X = se.symbols("x0 x1 x2 x3")

UNARY = [
    lambda a: se.sin(a), lambda a: se.cos(a), lambda a: se.exp(a / 4), lambda a: se.log(2 + a * a),
    lambda a: se.sqrt(1 + a * a), lambda a: se.tan(a / 4), lambda a: se.tanh(a),
    lambda a: (1 + a * a) ** se.Rational(-3, 2), lambda a: 1 / (2 + se.cos(a)),
]
BINARY = [
    lambda a, b: a + b, lambda a, b: a * b, lambda a, b: a - 2 * b, lambda a, b: a / (3 + b * b),
    lambda a, b: se.atan2(a, 2 + b * b), lambda a, b: (a * b) ** 2 / 5,
]


@st.composite
def graphs(draw):
    """(graph, output node, its written-out expression) of 3 to 12 nodes."""
    graph = Graph()
    values = list(X)            # what a new node may use: inputs and earlier nodes
    written = {x: x for x in X}
    for _ in range(draw(st.integers(3, 12))):
        if draw(st.booleans()):
            f = UNARY[draw(st.integers(0, len(UNARY) - 1))]
            a = values[draw(st.integers(0, len(values) - 1))]
            definition, expanded = f(a), f(written[a])
        else:
            f = BINARY[draw(st.integers(0, len(BINARY) - 1))]
            a = values[draw(st.integers(0, len(values) - 1))]
            b = values[draw(st.integers(0, len(values) - 1))]
            definition, expanded = f(a, b), f(written[a], written[b])
        node = graph.node(definition)
        written[node] = expanded
        values.append(node)
    out = values[-1]
    return graph, out, written[out]


POINT = {x: v for x, v in zip(X, (0.3, -0.7, 1.1, 0.45))}


def value(graph, expr):
    return graph.evaluator(list(X), [expr])([POINT[x] for x in X])[0]


def plain(expr):
    return float(expr.subs(POINT))


@settings(max_examples=60, deadline=None)
@given(graphs())
def test_diff_and_gradient_through_the_graph_equal_the_written_out_derivative(case):
    graph, out, expanded = case
    assert value(graph, out) == pytest.approx(plain(expanded), rel=1e-12, abs=1e-12)
    gradient = graph.gradient(out, X)
    for i, x in enumerate(X):
        expected = plain(expanded.diff(x))
        assert value(graph, graph.diff(out, x)) == pytest.approx(expected, rel=1e-10, abs=1e-10)
        assert value(graph, gradient[i]) == pytest.approx(expected, rel=1e-10, abs=1e-10)


@settings(max_examples=40, deadline=None)
@given(graphs())
def test_tangent_and_second_derivatives(case):
    """Directional derivative along (x1, x0*x2, 0, 1) and the Hessian row d2/dx0 dx_j, by a forward
    pass over the reverse-mode gradient (how the mass matrix is formed)."""
    graph, out, expanded = case
    direction = {X[0]: X[1], X[1]: X[0] * X[2], X[3]: 1}
    expected = plain(sum((expanded.diff(x) * d for x, d in direction.items()), se.Integer(0)))
    assert value(graph, graph.tangent(out, direction)) == pytest.approx(expected, rel=1e-10, abs=1e-10)
    first = graph.gradient(out, X)[0]
    for j, x in enumerate(X):
        expected = plain(expanded.diff(X[0]).diff(x))
        assert value(graph, graph.diff(first, x)) == pytest.approx(expected, rel=1e-9, abs=1e-9)


def test_identical_definitions_share_a_node_and_calls_are_computed_once():
    graph = Graph()
    a = graph.node(se.sin(X[0]) * X[1] + se.sin(X[0]))
    b = graph.node(se.sin(X[0]) * X[1] + se.sin(X[0]))
    assert a == b
    sin_nodes = [s for s, d in graph.used_nodes([a]) if d == se.sin(X[0])]
    assert len(sin_nodes) == 1
    assert graph.inputs_of(a) == {X[0], X[1]}


def test_derivatives_only_touch_the_nodes_an_expression_uses():
    """A forward pass differentiates the nodes the expression uses, not the whole graph: asking
    for many derivatives of a small expression does not grow with the rest of the graph."""
    graph = Graph()
    big = X[0]
    for k in range(200):
        big = graph.node(se.sin(big) + X[1] * k)
    small = graph.node(X[0] * X[1] + 1)
    before = len(graph)
    for x in X:
        graph.diff(small, x)
    assert len(graph) - before <= 4


def test_chain_sizes_stay_linear():
    """A chain of rotations R_k = R_{k-1} Rz(x_k) (3 x 3 entries as nodes): the graph grows by a
    fixed number of nodes per link, its gradient too, where the written-out entries triple."""
    sizes = []
    for links in (4, 8, 16):
        graph = Graph()
        xs = se.symbols(f"a0:{links}")
        R = [[se.Integer(int(i == j)) for j in range(3)] for i in range(3)]
        for k, x in enumerate(xs):
            c, s = se.cos(x), se.sin(x)
            rot = [[c, -s, 0], [s, c, 0], [0, 0, 1]] if k % 2 == 0 else [[c, 0, s], [0, 1, 0], [-s, 0, c]]
            R = [[graph.node(sum(R[i][k] * rot[k][j] for k in range(3))) for j in range(3)] for i in range(3)]
        before = len(graph)
        graph.gradient(R[0][2] + R[1][1], xs)
        sizes.append((before, len(graph) - before))
    (n4, g4), (n8, g8), (n16, g16) = sizes
    assert n16 - n8 <= 2.5 * (n8 - n4)
    assert g16 <= 5 * g4 + 40


def test_evaluator_matches_math():
    graph = Graph()
    node = graph.node(se.exp(X[0]) * se.atan2(X[1], X[2]) + se.sqrt(X[3]))
    got = graph.evaluator(list(X), [node, node * 2])([0.3, -0.7, 1.1, 0.45])
    expected = math.exp(0.3) * math.atan2(-0.7, 1.1) + math.sqrt(0.45)
    assert np.allclose(got, [expected, 2 * expected], rtol=1e-14)
