"""The kernel printer on every node shape a derivation can produce, evaluated against sympy's own
numeric evaluation (evalf with the symbols substituted), never against another printer.

The first of these cases caught the bug of the first release: ``a/x**2`` printed as ``a/x*x``.
"""

import math

import pytest
import sympy as sp

from lagrange_gen.codegen.printer import KernelPrinter

x, y, z = sp.symbols("x y z", real=True)
a, b = sp.symbols("a b", positive=True)
VALUES = {x: 0.73, y: -1.31, z: 2.17, a: 1.9, b: 0.61}

SHAPES = [
    # powers in denominators (the Kepler bug), of symbols, sums and functions
    a / x**2, a / x**3, a / x**4, 1 / (x**2 * y**3), a / (x + y)**2, sp.sin(x)**4 / a**2,
    a**2 / b**2, x / (y * z**2), (x**2 / y**2)**3, 1 / (a * x)**2,
    # negative and nested powers
    x**-1, x**-2, x**-5, (x + y)**-3, (-x)**3, (-x)**2, (-y)**4, (x - y)**5, (a + b)**-2,
    x**2 * y**-2 * z**3, -x**2, -(x**2), (-x**2)**3, x**(-sp.Rational(3, 2)) * 0 + a**(-sp.Rational(3, 2)),
    # nested divisions and unary minus
    1 / (1 / x + 1 / y), x / (y / z), (x / y) / (z / a), -x / y, -(x + y) / -(z - a), 1 / (-x),
    x - (y - z), x - (-y), -(-x), a * (-x) ** 2 / (-(y**2)),
    # rational and float exponents
    a**sp.Rational(1, 2), a**sp.Rational(-1, 2), a**sp.Rational(3, 2), a**sp.Rational(-5, 3),
    (x**2 + a)**sp.Rational(3, 2), (x**2 + a)**sp.Rational(-3, 2), a**0.37, a**-1.5, x**2.0,
    (a + b)**sp.Float("2.5"), a**(1 / x), a**(-1 / x), a**(x**2), sp.Pow(1 / a, x, evaluate=False),
    sp.Pow(x**2, -1, evaluate=False), sp.Pow(x**2, 3, evaluate=False) / y, (x**3)**-1 * a,
    # exponentials and logarithms with symbolic exponents
    2**x, 2**(-x), sp.exp(x), sp.exp(-x**2 / a), a**x, x**y * 0 + a**(y / z), sp.log(a), sp.log(a**2 + x**2),
    sp.log(b) / sp.log(a), sp.sqrt(a), sp.sqrt(x**2 + y**2), 1 / sp.sqrt(x**2 + y**2),
    1 / sp.sqrt(x**2 + y**2)**3, sp.sqrt(a) ** 3, sp.cbrt(a), sp.E**x,
    # trig, inverse trig, hyperbolic
    sp.sin(x), sp.cos(x)**2, 1 / sp.cos(x)**2, sp.tan(x), sp.cot(y), sp.sec(x), sp.csc(y),
    sp.atan2(y, x), sp.atan2(-y, -x), sp.atan(x / y), sp.asin(x / z), sp.acos(x / z),
    sp.sinh(x), sp.cosh(x), sp.tanh(y), 1 / sp.cosh(x)**2,
    # nonsmooth nodes the derivation can produce
    sp.Abs(y), sp.Abs(x - y) * y, sp.sign(y), sp.sign(x) * x, sp.Heaviside(x), sp.Heaviside(y),
    sp.Piecewise((x**2, x < y), (y, True)), sp.Piecewise((1 / x, y > 0), (-x, True)),
    sp.Min(x, y, z), sp.Max(x, y), sp.Max(x, y)**2, 1 / sp.Min(x, z)**2,
    # rationals and integer literals in every position
    sp.Rational(1, 3) * x, x / 3, 3 / x, sp.Rational(-2, 7) / x**2, x + sp.Rational(1, 2),
    sp.Integer(-7) * x**3, sp.pi * x, sp.E * x, x * sp.Float("1e-300"), x * sp.Float("1e300"),
]


def _evaluate(text):
    env = {"math": math}
    env.update({s.name: v for s, v in VALUES.items()})
    return eval(text, env)  # noqa: S307 - the printer's own output on fixed numbers


@pytest.mark.parametrize("expr", SHAPES, ids=[sp.sstr(e) for e in SHAPES])
def test_printed_expression_evaluates_like_sympy(expr):
    text = KernelPrinter().doprint(expr)
    expected = complex(sp.N(expr.subs(VALUES), 30))
    assert abs(expected.imag) < 1e-12, f"test case {expr} is not real at the sample point"
    got = _evaluate(text)
    assert got == pytest.approx(expected.real, rel=1e-13, abs=1e-300), f"{expr} printed as {text}"


def test_division_by_squared_symbol_is_parenthesized():
    """The printed text for the Kepler momentum rate: -1/r**2 + r*phidot**2."""
    r, phid = sp.symbols("q_0 qd_1", positive=True)
    text = KernelPrinter().doprint(-1 / r**2 + r * phid**2)
    assert "1/q_0*q_0" not in text.replace(" ", "")
    assert _evaluate_with(text, q_0=2.0, qd_1=0.5) == pytest.approx(-0.25 + 0.5)


def _evaluate_with(text, **values):
    return eval(text, {"math": math, **values})  # noqa: S307
