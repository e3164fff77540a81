"""Print sympy expressions as numba-friendly Python over placeholder locals (q_0, qd_1, p_2, t).

Inputs maps a model's symbols to those placeholders and to the statements that load them from
the kernel's argument arrays (q_0 = q[0]); KernelPrinter prints any Symbol by its name.
"""

from __future__ import annotations

import sympy as sp
from sympy.printing.precedence import PRECEDENCE
from sympy.printing.pycode import PythonCodePrinter

from ..derive.kinks import settle_derivatives


class KernelPrinter(PythonCodePrinter):
    """PythonCodePrinter with math.* calls; Symbols (placeholders, CSE temporaries) by name.

    order="none": Add terms in sympy's canonical args order (deterministic) instead of sorting
    every sum for display, which was a third of the printing time of large kernels."""

    def __init__(self):
        super().__init__({"fully_qualified_modules": True, "standard": "python3", "order": "none"})

    def _print_Symbol(self, expr):
        return expr.name

    def _print_DiracDelta(self, expr):
        # Derivatives of sign/Heaviside (e.g. the Jacobian of a drag -c |v| v): zero everywhere
        # except at the kink, where any element of the generalized Jacobian will do for Newton.
        return "0.0"

    def _print_frac(self, expr):
        # sympy prints frac(x) as ``x % 1`` unparenthesized: a*frac(x) read (a*x) % 1.
        return f"({self._print(expr.args[0])} % 1)"

    def _print_Derivative(self, expr):
        # What sympy leaves unevaluated: 0 for floor/ceiling (derive/kinks.py), else refused.
        return self._print(settle_derivatives(expr, "a generated kernel"))

    def _print_Rational(self, expr):
        return f"{float(expr)!r}"

    def _print_Half(self, expr):
        return "0.5"

    def _print_Integer(self, expr):
        return f"{int(expr)}"

    def _print_Float(self, expr):
        return repr(float(expr))

    def _print_Pow(self, expr, rational=False):
        base, exp = expr.args
        if exp.is_Integer and 2 <= int(exp) <= 4 and base.is_Symbol:
            # A product is cheaper than pow in numba, but it must stay one factor wherever the
            # power sits: the parent printed it as a Pow (tighter than Mul), so ``a/x**2`` would
            # otherwise read ``a/x*x``. The parentheses make the product an atom.
            return "(" + "*".join([self._print(base)] * int(exp)) + ")"
        if exp == -1:
            return f"1.0/{self.parenthesize(base, PRECEDENCE['Pow'])}"
        return super()._print_Pow(expr, rational=rational)


class Inputs:
    """The input symbols of a model's kernels and their placeholders.

    rename: {model symbol: placeholder name}; loads(args): [(placeholder, load text)] for the
    kernel arguments ``args`` in order, e.g. ("q_0", "q[0]"); ``t`` is a scalar argument.
    graph: the expression graph of a model derived through one (derive/graph.py), whose nodes
    the kernels use, else None.
    """

    _VECTORS = ("q", "qd", "qdd", "p", "w", "lam", "we", "mu")

    def __init__(self, dyn):
        symbols = {"q": dyn.q, "qd": dyn.qd, "qdd": dyn.aux.get("qdd", []), "p": dyn.params, "w": dyn.aux["w"],
                   "lam": dyn.aux["lam"], "we": dyn.aux.get("we", []), "mu": dyn.aux.get("mu", [])}
        self.graph = getattr(dyn.ops, "graph", None)
        self.rename = {dyn.t: "t"}
        self._loads = {}
        for arg in self._VECTORS:
            self._loads[arg] = [(f"{arg}_{i}", f"{arg}[{i}]") for i in range(len(symbols[arg]))]
            for i, s in enumerate(symbols[arg]):
                self.rename[s] = f"{arg}_{i}"
        # generalized forces given to a kernel (forward_dynamics_torques) are the w symbols
        self._loads["tau"] = [(f"w_{i}", f"tau[{i}]") for i in range(len(symbols["w"]))]

    def loads(self, args):
        return [pair for arg in args for pair in self._loads.get(arg, [])]


#: symengine function names -> the Python text of the call (the graph path's printer).
_NATIVE_CALLS = {name: f"math.{name}" for name in
                 ("sin", "cos", "tan", "asin", "acos", "atan", "atan2", "sinh", "cosh", "tanh",
                  "asinh", "acosh", "atanh", "exp", "log", "sqrt", "erf", "erfc", "gamma")}
_NATIVE_CALLS["Abs"] = "abs"
_ATOMIC = ("Symbol", "Integer", "One", "Zero", "NegativeOne")


def print_native(expr) -> str:
    """Python text of a symengine expression, read directly from its tree (the nodes of an
    expression graph are many and short: converting each to sympy to print it cost more than
    the whole derivation). Prints what KernelPrinter prints for the same expression up to
    term order; anything it does not know goes through sympy and KernelPrinter."""
    kind = type(expr).__name__
    if kind == "Symbol":
        return expr.name
    if expr.is_Integer:
        return str(int(expr))
    if expr.is_Number:
        return repr(float(expr))
    if kind == "Add":
        text = ""
        for i, arg in enumerate(expr.args):
            term = print_native(arg)
            if i == 0:
                text = term
            elif term.startswith("-"):
                text += " - " + term[1:]
            else:
                text += " + " + term
        return text
    if kind == "Mul":
        args = list(expr.args)
        sign = ""
        if args[0].is_Number and float(args[0]) < 0:
            sign, args[0] = "-", -args[0]
            if args[0] == 1:
                args = args[1:]
        factors = [_factor(a) for a in args]
        return sign + "*".join(factors)
    if kind == "Pow":
        base, exp = expr.args
        if type(base).__name__ == "Exp1":
            return f"math.exp({print_native(exp)})"
        if exp.is_Integer and 2 <= int(exp) <= 4 and type(base).__name__ == "Symbol":
            return "(" + "*".join([base.name] * int(exp)) + ")"
        if exp.is_Integer and int(exp) == -1:
            return f"1.0/{_factor(base)}"
        if exp.is_Number and float(exp) == 0.5:
            return f"math.sqrt({print_native(base)})"
        return f"{_factor(base)}**{_factor(exp)}"
    if kind in _NATIVE_CALLS and expr.args:
        return f"{_NATIVE_CALLS[kind]}({', '.join(print_native(a) for a in expr.args)})"
    if kind == "Pi":
        return "math.pi"
    if kind == "Exp1":
        return "math.e"
    return KernelPrinter().doprint(sp.sympify(expr))


def _factor(expr) -> str:
    """An operand of * or **: parenthesized unless it is atomic or a call."""
    text = print_native(expr)
    kind = type(expr).__name__
    if kind in _ATOMIC or kind in _NATIVE_CALLS or (kind == "Pow" and text.startswith(("math.", "("))):
        return text
    if expr.is_Number and not text.startswith("-"):
        return text
    return f"({text})"
