"""Print sympy expressions as numba-friendly Python: coordinates become q[i], parameters p[k]."""

from __future__ import annotations

import sympy as sp
from sympy.printing.precedence import PRECEDENCE
from sympy.printing.pycode import PythonCodePrinter


class KernelPrinter(PythonCodePrinter):
    """PythonCodePrinter with a symbol table (symbol -> array element text) and math.* calls."""

    def __init__(self, names):
        super().__init__({"fully_qualified_modules": True, "standard": "python3"})
        self._names = names

    def _print_Symbol(self, expr):
        name = self._names.get(expr)
        if name is None:
            return expr.name  # a CSE temporary
        return name

    _print_Coordinate = _print_Velocity = _print_Parameter = _print_Symbol

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
            b = self.parenthesize(base, PRECEDENCE["Mul"] + 1)
            return "*".join([b] * int(exp))
        if exp == -1:
            return f"1.0/{self.parenthesize(base, PRECEDENCE['Pow'])}"
        return super()._print_Pow(expr, rational=rational)


def symbol_table(dyn):
    """Map every sympy symbol a kernel may see to its array-element text."""
    names = {}
    for i, s in enumerate(dyn.q):
        names[s] = f"q[{i}]"
    for i, s in enumerate(dyn.qd):
        names[s] = f"qd[{i}]"
    for k, s in enumerate(dyn.params):
        names[s] = f"p[{k}]"
    for i, s in enumerate(dyn.aux["w"]):
        names[s] = f"w[{i}]"
    for i, s in enumerate(dyn.aux["lam"]):
        names[s] = f"lam[{i}]"
    for i, s in enumerate(dyn.aux.get("we", [])):
        names[s] = f"we[{i}]"
    names[dyn.t] = "t"
    return names
