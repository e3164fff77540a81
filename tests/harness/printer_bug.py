"""The printer bug of issue 10 put back in-process: ``x**k`` of a symbol (k = 2..4) printed as a
bare product, so ``a/x**2`` reads ``a/x*x`` (the code before commit 13480af). For the mutation
test and ``--printer-bug``; printer.py itself is never edited."""

from __future__ import annotations

from sympy.printing.precedence import PRECEDENCE

from lagrange_gen.codegen.printer import KernelPrinter

FIXED_PRINT_POW = KernelPrinter._print_Pow


def buggy_print_pow(self, expr, rational=False):
    base, exp = expr.args
    if exp.is_Integer and 2 <= int(exp) <= 4 and base.is_Symbol:
        b = self.parenthesize(base, PRECEDENCE["Mul"] + 1)
        return "*".join([b] * int(exp))
    return FIXED_PRINT_POW(self, expr, rational=rational)


def put_back(monkeypatch=None):
    """Install the buggy _print_Pow (through monkeypatch when given, so the test undoes it)."""
    if monkeypatch is not None:
        monkeypatch.setattr(KernelPrinter, "_print_Pow", buggy_print_pow)
    else:
        KernelPrinter._print_Pow = buggy_print_pow
