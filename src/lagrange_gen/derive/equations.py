"""The derived equations, to read: ``lg.equations(model)`` and ``lagrange-gen equations``.

    H(q) qddot + h(q, qdot) + g(q) = Q(q, qdot, t) + J(q)^T lambda,    Phi(q) = 0,
    J(q) qddot = gamma(q, qdot)     (gamma = -(dJ/dq . qdot) qdot, the constraints differentiated
                                     twice in time)

H (n, n) is the mass matrix d2T/dqdot2, h (n, 1) the Coriolis/centrifugal terms, g (n, 1) = dV/dq,
Q (n, 1) the generalized forces (forces= and -dD/dqdot of the dissipation), Phi (m, 1) the
constraints, J (m, n) = dPhi/dq. They come from the same derivation the code generator prints
(lagrange_gen.derive), as sympy matrices; entries small enough are simplified.

``Equations.latex()`` prints the assembled equation in matrix form (bmatrix), coordinates and
velocities as a reader writes them (th1 -> \\theta_{1}, th1_dot -> \\dot{\\theta}_{1}); when an
entry is large, the subexpressions the entries share are printed once, after the equations.
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp
from sympy.printing.conventions import split_super_sub
from sympy.printing.latex import translate

#: Entries with at most this many operations (sp.count_ops) are simplified; larger ones are
#: left as derived (simplify's cost grows quickly with size, and big entries rarely shrink).
SIMPLIFY_MAX_OPS = 80
#: Models with more coordinates than this are not simplified at all.
SIMPLIFY_MAX_COORDS = 12
#: When an entry has more operations than this, latex() prints the subexpressions the entries
#: share once (sympy's cse) instead of repeating them: a robot's entries run to thousands of
#: operations, whose LaTeX takes seconds to print and pages to read.
CSE_MIN_OPS = 200
#: Coordinate names that abbreviate a Greek letter (th1 -> \theta_{1}).
ABBREVIATIONS = {"th": "theta"}
#: Names of the shared subexpressions, the first not used by the model.
SHARED_STEMS = ("xi", "zeta", "chi", "varsigma")

NAMES = ("H", "h", "g", "Q", "Phi", "J", "gamma")
MEANING = {"H": "mass matrix d2T/dqdot2", "h": "Coriolis and centrifugal terms",
           "g": "conservative forces dV/dq", "Q": "generalized forces (forces and -dD/dqdot)",
           "Phi": "holonomic constraints Phi(q) = 0", "J": "constraint Jacobian dPhi/dq",
           "gamma": "-(dJ/dq . qdot) qdot, so that J qddot = gamma"}


@dataclass
class Equations:
    """H (n, n), h, g, Q (n, 1), Phi (m, 1), J (m, n), gamma (m, 1) as sympy Matrices, and the
    model's coordinates, velocities and parameters (sympy symbols, PARAMS order)."""

    name: str
    coords: list
    velocities: list
    params: list
    H: sp.Matrix
    h: sp.Matrix
    g: sp.Matrix
    Q: sp.Matrix
    Phi: sp.Matrix
    J: sp.Matrix
    gamma: sp.Matrix

    def items(self):
        """(name, matrix) in the order H, h, g, Q, Phi, J, gamma, without the empty constraint
        matrices of an unconstrained model."""
        return [(k, getattr(self, k)) for k in NAMES if getattr(self, k).shape[0]]

    def __str__(self):
        head = (f"model {self.name}: H qddot + h + g = Q" + (" + J^T lambda" if self.Phi.shape[0] else "")
                + f"\ncoordinates q = ({', '.join(map(str, self.coords))}), "
                f"velocities ({', '.join(map(str, self.velocities))}), "
                f"parameters ({', '.join(map(str, self.params)) or 'none'})")
        parts = [f"{k} ({MEANING[k]}) =\n{sp.pretty(v, use_unicode=False, wrap_line=False)}"
                 for k, v in self.items()]
        return "\n\n".join([head] + parts)

    def latex(self):
        """The equations as LaTeX, one per line, each the body of a display equation (matrices
        as bmatrix): H qddot + h + g = Q (+ J^T lambda), and for a constrained model Phi = 0
        and J qddot = gamma; zero terms left out. Lines starting with % are comments: the
        equation in words first, then, when the entries are large (CSE_MIN_OPS), the shared
        subexpressions they use."""
        names = latex_symbol_names(self.coords, self.velocities)
        used = {s.name for s in self.params} | {s.name for s in self.coords}
        accelerations = [sp.Dummy(f"{c.name}_ddot") for c in self.coords]
        for c, a in zip(self.coords, accelerations):
            stem, scripts = _stem_and_scripts(c.name)
            names[a] = rf"\ddot{{{stem}}}{scripts}"
        multipliers = [sp.Dummy(f"lambda_{i + 1}") for i in range(self.Phi.shape[0])]
        names.update({lam: rf"\lambda_{{{i + 1}}}" for i, lam in enumerate(multipliers)})
        mats, shared = _shared_subexpressions(dict(self.items()), used, names)

        def tex(matrix):
            rows = [" & ".join(sp.latex(e, symbol_names=names) for e in matrix.row(i))
                    for i in range(matrix.rows)]
            return r"\begin{bmatrix} " + r" \\ ".join(rows) + r" \end{bmatrix}"

        qdd, lam = sp.Matrix(accelerations), sp.Matrix(multipliers)
        left = [f"{tex(mats['H'])} {tex(qdd)}"] + [tex(mats[k]) for k in ("h", "g")
                                                      if not mats[k].is_zero_matrix]
        right = [tex(mats["Q"])] if not mats["Q"].is_zero_matrix else []
        constrained = self.Phi.shape[0] > 0
        if constrained:
            right.append(f"{tex(mats['J'].T)} {tex(lam)}")
        lines = [f"% model {self.name}: H(q) qddot + h(q, qdot) + g(q) = Q"
                 + (" + J(q)^T lambda, Phi(q) = 0, J(q) qddot = gamma" if constrained else ""),
                 " + ".join(left) + " = " + (" + ".join(right) or "0")]
        if constrained:
            lines.append(f"{tex(mats['Phi'])} = 0")
            lines.append(f"{tex(mats['J'])} {tex(qdd)} = {tex(mats['gamma'])}")
        if shared:
            lines.append("% where")
            lines += [f"{names[s]} = {sp.latex(e, symbol_names=names)}" for s, e in shared]
        return "\n".join(lines)


def latex_symbol_names(coords, velocities=None) -> dict:
    """{symbol: LaTeX} of coordinates and their velocities (default Coordinate.d): Greek names
    and their abbreviations (ABBREVIATIONS) as letters, the rest of a name as a subscript,
    velocities dotted: th1 -> \\theta_{1}, th1_dot -> \\dot{\\theta}_{1}, x_c -> x_{c}."""
    velocities = [c.d for c in coords] if velocities is None else velocities
    names = {}
    for c, v in zip(coords, velocities):
        stem, scripts = _stem_and_scripts(c.name)
        names[c] = stem + scripts
        names[v] = rf"\dot{{{stem}}}{scripts}"
    return names


def _stem_and_scripts(name):
    """('\\theta', '_{1}') for 'th1': the letter and its sub- and superscripts."""
    stem, supers, subs = split_super_sub(name)
    letter = translate(ABBREVIATIONS.get(stem, stem))
    scripts = (f"_{{{' '.join(subs)}}}" if subs else "") + (f"^{{{' '.join(supers)}}}"
                                                            if supers else "")
    return letter, scripts


def _shared_subexpressions(mats, used, names):
    """(matrices, [(symbol, expression)]): when an entry has more than CSE_MIN_OPS operations,
    the matrices over the shared subexpressions (named \\xi_{k}, or the first stem of
    SHARED_STEMS the model does not use, added to ``names``); else the matrices as given and
    []."""
    entries = [e for m in mats.values() for e in m]
    if not any(_larger_than(e, CSE_MIN_OPS) for e in entries):
        return mats, []
    stem = next((s for s in SHARED_STEMS if not any(u.startswith(s) for u in used)), "xi")
    symbols = sp.numbered_symbols(stem, cls=sp.Dummy)
    shared, reduced = sp.cse(entries, symbols=symbols, order="none")
    for k, (symbol, _) in enumerate(shared):
        names[symbol] = rf"\{stem}_{{{k}}}"
    out, at = {}, 0
    for key, m in mats.items():
        out[key] = sp.Matrix(m.rows, m.cols, reduced[at:at + len(m)])
        at += len(m)
    return out, shared


def _larger_than(expr, limit):
    """Whether ``expr`` has more than ``limit`` nodes (cheap: stops counting at limit + 1);
    nodes bound sp.count_ops from above, which costs seconds on a robot's entries."""
    for count, _ in enumerate(sp.preorder_traversal(expr)):
        if count >= limit:
            return True
    return False


def equations(model, simplify=True, **options) -> Equations:
    """The equations of motion of ``model`` (a Model, or the path of a model file, with
    ``options`` for its build()) as an :class:`Equations` of sympy matrices.

    simplify: simplify entries with at most SIMPLIFY_MAX_OPS operations (models with at most
    SIMPLIFY_MAX_COORDS coordinates); False returns them as derived.
    """
    from . import derive
    from ..model.model import Model
    from ..model.model_file import load_model
    if not isinstance(model, Model):
        model = load_model(model, **options)
    d = derive(model)
    tidy = _simplifier(simplify and d.n <= SIMPLIFY_MAX_COORDS)
    mats = {k: sp.Matrix(getattr(d, k)).applyfunc(tidy) for k in NAMES}
    return Equations(model.name, list(model.coords), list(model.velocities), list(model.params),
                     **mats)


def _simplifier(enabled):
    def tidy(expr):
        if not enabled or _larger_than(expr, 4 * SIMPLIFY_MAX_OPS) or \
                sp.count_ops(expr) > SIMPLIFY_MAX_OPS:
            return expr
        return sp.simplify(expr)
    return tidy
