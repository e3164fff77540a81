"""Print sympy expressions as numba-friendly Python over placeholder locals (q_0, qd_1, p_2, t).

Inputs maps a model's symbols to those placeholders and to the statements that load them from
the kernel's argument arrays (q_0 = q[0]); KernelPrinter prints any Symbol by its name.
"""

from __future__ import annotations

import sympy as sp
from sympy.printing.precedence import PRECEDENCE
from sympy.printing.pycode import PythonCodePrinter


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
    """

    _VECTORS = ("q", "qd", "p", "w", "lam", "we")

    def __init__(self, dyn):
        symbols = {"q": dyn.q, "qd": dyn.qd, "p": dyn.params, "w": dyn.aux["w"],
                   "lam": dyn.aux["lam"], "we": dyn.aux.get("we", [])}
        self.rename = {dyn.t: "t"}
        self._loads = {}
        for arg in self._VECTORS:
            self._loads[arg] = [(f"{arg}_{i}", f"{arg}[{i}]") for i in range(len(symbols[arg]))]
            for i, s in enumerate(symbols[arg]):
                self.rename[s] = f"{arg}_{i}"

    def loads(self, args):
        return [pair for arg in args for pair in self._loads.get(arg, [])]
