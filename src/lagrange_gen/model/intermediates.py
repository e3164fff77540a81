"""Intermediate symbols: a symbol that stands for its definition, so that energies built from
bodies stay short sums over shared subexpressions (model/bodies.py makes them; derive/graph.py
differentiates through them and never expands them)."""

from __future__ import annotations

import itertools

import sympy as sp

__all__ = ["Intermediate", "new_intermediate", "intermediates_of", "expand_intermediates"]


#: Serial numbers of Intermediates (their names), in creation order.
_serials = itertools.count(1)


class Intermediate(sp.Symbol):
    """A symbol standing for ``definition`` (a sympy expression of coordinates, velocities,
    parameters, t and other Intermediates). The definition is part of the symbol's identity, as
    a Parameter's declaration is, so sympy's cache never mixes two of the same name."""

    __slots__ = ("definition",)

    def __new__(cls, name, definition):
        obj = sp.Symbol.__xnew__(cls, name, real=True)
        obj.definition = sp.sympify(definition)
        return obj

    def __getnewargs_ex__(self):
        return ((self.name, self.definition), {})

    def _hashable_content(self):
        return super()._hashable_content() + (self.definition,)


def new_intermediate(definition):
    """A fresh Intermediate named k<serial>, serials counting up in creation order in this
    process (the order ``_in_order`` sorts by)."""
    return Intermediate(f"k{next(_serials)}", definition)


def intermediates_of(*exprs):
    """[Intermediate] that ``exprs`` use, directly or through other definitions, each after
    the ones its definition uses."""
    order, seen = [], set()
    for expr in exprs:
        stack = [(s, False) for s in _in_order(sp.sympify(expr).atoms(Intermediate))]
        while stack:
            sym, ready = stack.pop()
            if sym in seen:
                continue
            if ready:
                seen.add(sym)
                order.append(sym)
                continue
            stack.append((sym, True))
            stack.extend((u, False) for u in _in_order(sym.definition.atoms(Intermediate)) if u not in seen)
    return order


def _in_order(intermediates):
    """Intermediates in creation order (their names k<serial>): the derivation numbers its graph
    nodes in this order, so the generated text must not follow a set's order."""
    return sorted(intermediates, key=lambda s: int(s.name[1:]))


def expand_intermediates(expr):
    """``expr`` with every Intermediate replaced by its definition, recursively (exponential on
    deep trees: for models whose derivation cannot use the graph, and for tests)."""
    expr = sp.sympify(expr)
    values = {}
    for sym in intermediates_of(expr):
        values[sym] = sym.definition.xreplace({u: values[u] for u in sym.definition.atoms(Intermediate)})
    return expr.xreplace(values) if values else expr
