"""Symbolic backend of the derivation: symengine when installed, sympy otherwise.

The derivation runs entirely in one backend's *native* objects (``Ops``): on a 20-link pendulum
converting every intermediate symengine result back to sympy would take about half of the derivation
(profiled), and sympy's matrix products another fifth. Results are converted to sympy only when
someone reads a Dynamics field (tests, small models); code generation reads the native expressions
directly.
Native symbols carry only names; ``to_sympy`` maps them back to the model's symbols by name.

``jacobian``/``gradient`` (sympy in, sympy out) remain for callers that work in sympy.
"""

from __future__ import annotations

import numpy as np
import sympy as sp

from .kinks import NUMERIC_FUNCTIONS, settle_derivatives

try:  # optional accelerator
    import symengine as _se
except ImportError:  # pragma: no cover - exercised only where symengine is absent
    _se = None

BACKEND = "symengine" if _se is not None else "sympy"


class Ops:
    """Native matrix/expression operations of one backend (``ops()`` picks the current one)."""

    def __init__(self, name):
        self.name = name
        self._lib = _se if name == "symengine" else sp

    def native(self, expr):
        """A sympy expression (or number) as a native expression."""
        return _se.sympify(expr) if self.name == "symengine" else sp.sympify(expr)

    def symbols(self, syms):
        return [self.native(s) for s in syms]

    def matrix(self, rows, cols, entries):
        return Mat(rows, cols, [self.native(e) for e in entries])

    def column(self, entries):
        entries = list(entries)
        return self.matrix(len(entries), 1, entries)

    def zeros(self, rows, cols):
        return self.matrix(rows, cols, [0] * (rows * cols))

    def jacobian(self, exprs, variables):
        """d exprs_i / d variables_j as a native (len(exprs), len(variables)) matrix."""
        exprs, variables = list(exprs), list(variables)
        return self.matrix(len(exprs), len(variables), [e.diff(v) for e in exprs for v in variables])

    def lambdify(self, args, exprs):
        """Numeric evaluator f(values (len(args),)) -> float array (len(exprs),) for checks."""
        if self.name == "symengine":
            try:
                f = _se.Lambdify(list(args), list(exprs), backend="lambda")
                return lambda values: np.asarray(f(np.asarray(values, dtype=float)), dtype=float).ravel()
            except Exception:  # noqa: BLE001  a function symengine cannot evaluate: use sympy
                pass
        names = {str(a): sp.Symbol(str(a)) for a in args}
        exprs = [settle_derivatives(self.to_sympy(e, names)) for e in exprs]
        f = sp.lambdify([list(names.values())], exprs, modules=[NUMERIC_FUNCTIONS, "numpy"])
        return lambda values: np.asarray(f(list(values)), dtype=float).ravel()

    def to_sympy(self, obj, names):
        """Native expression or matrix -> sympy, symbols mapped to ``names`` {name: sympy symbol}."""
        if isinstance(obj, Mat):
            return sp.Matrix(obj.rows, obj.cols, [self.to_sympy(e, names) for e in obj.entries])
        out = sp.sympify(obj)
        free = out.free_symbols
        return out.xreplace({s: names[s.name] for s in free if s.name in names}) if free else out


class Mat:
    """A dense matrix of native expressions, row-major. Arithmetic is written out as explicit
    sums in the derivation (skipping structural zeros), so this only stores and indexes; it also
    keeps shapes with a zero dimension, which symengine's DenseMatrix collapses to 0 x 0."""

    def __init__(self, rows, cols, entries):
        if len(entries) != rows * cols:
            raise ValueError(f"Mat: {len(entries)} entries for shape ({rows}, {cols})")
        self.rows, self.cols, self.entries = rows, cols, entries

    @property
    def shape(self):
        return (self.rows, self.cols)

    def __getitem__(self, index):
        i, j = index
        return self.entries[i * self.cols + j]

    def __iter__(self):
        return iter(self.entries)

    def __len__(self):
        return len(self.entries)

    @property
    def free_symbols(self):
        out = set()
        for e in self.entries:
            out |= set(e.free_symbols)
        return out


#: symengine functions whose derivatives symengine writes in closed form. Others (Abs, sign,
#: Min, Piecewise, sympy-only functions wrapped as PyFunction, ...) come back as unevaluated
#: Derivative objects that cannot be printed, so a model using them is derived by sympy.
_SMOOTH = {"sin", "cos", "tan", "cot", "sec", "csc", "asin", "acos", "atan", "acot", "asec", "acsc",
           "sinh", "cosh", "tanh", "coth", "sech", "csch", "asinh", "acosh", "atanh", "acoth",
           "exp", "log", "atan2", "LambertW", "erf", "erfc", "gamma"}


def backend_for(exprs, backend=None) -> str:
    """The backend to derive ``exprs`` (sympy expressions) with: BACKEND (or ``backend``),
    unless symengine cannot convert them or differentiate one of their functions exactly."""
    name = backend or BACKEND
    if name != "symengine" or _se is None:
        return "sympy"
    try:
        for expr in exprs:
            if any(type(f).__name__ not in _SMOOTH for f in _se.sympify(expr).atoms(_se.Function)):
                return "sympy"
    except Exception:  # noqa: BLE001  not representable in symengine
        return "sympy"
    return "symengine"


def ops(backend=None) -> Ops:
    """The Ops of ``backend`` (default: the module-level BACKEND, read at call time)."""
    name = backend or BACKEND
    return Ops(name if (name != "symengine" or _se is not None) else "sympy")


def jacobian(exprs, variables, backend=None):
    """d exprs_i / d variables_j as a sympy Matrix (len(exprs), len(variables))."""
    exprs, variables = list(exprs), list(variables)
    if not exprs or not variables:
        return sp.zeros(len(exprs), len(variables))
    o = ops(backend)
    if o.name == "symengine":
        try:
            names = {s.name: s for e in exprs for s in e.free_symbols}
            names.update({v.name: v for v in variables})
            return o.to_sympy(o.jacobian(o.symbols(exprs), o.symbols(variables)), names)
        except Exception:  # noqa: BLE001  any symengine failure: sympy is slower but always right
            pass
    return sp.Matrix(exprs).jacobian(variables)


def gradient(expr, variables, backend=None):
    """d expr / d variables_j as a sympy column Matrix (len(variables), 1)."""
    return jacobian([expr], variables, backend).T
