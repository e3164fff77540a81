"""Common-subexpression elimination of one kernel's outputs, on plain placeholder symbols.

The kernel's inputs are renamed to the local variable names the kernel loads them into (q_0,
qd_3, p_1, t, ...) before CSE, so the printed code needs no symbol table and a user symbol can
never collide with a temporary (temporaries are x0, x1, ...; placeholders contain "_" or are "t").

symengine's CSE (C++) is used when installed: on a 12-link pendulum it is ~15x faster than
sympy's and finds fewer operations (1892 against 2310 for dynamics). Any expression symengine
cannot represent falls back to sympy's cse, whose output is numerically the same.
"""

from __future__ import annotations

import sympy as sp

from ..derive.backend import BACKEND
from ..derive.kinks import settle_derivatives

try:  # optional accelerator (a dependency, but the sympy path must keep working without it)
    import symengine as _se
except ImportError:  # pragma: no cover
    _se = None


def cse(exprs, rename, backend=None):
    """Return (temps, reduced) for sympy expressions ``exprs``.

    rename: {sympy Symbol: placeholder name} for every input symbol. temps: [(name, sympy
    expr)] in evaluation order; reduced: one sympy expression per input expression, both over
    plain Symbols named by placeholders and temporaries. Deterministic for the same input.
    """
    # Before symengine sees them: it drops some unevaluated derivatives (derive/kinks.py).
    exprs = [settle_derivatives(e, "a generated kernel") for e in exprs]
    if not exprs:
        return [], []
    if (backend or BACKEND) == "symengine" and _se is not None:
        try:
            return _cse_symengine(exprs, rename)
        except Exception:  # noqa: BLE001  unsupported function etc.: sympy is slower but complete
            pass
    return _cse_sympy(exprs, rename)


def _cse_symengine(exprs, rename):
    sub = {_se.Symbol(s.name): _se.Symbol(new) for s, new in rename.items()}
    converted = [_se.sympify(e).xreplace(sub) for e in exprs]
    temps, reduced = _se.cse(converted)
    return [(str(sym), sp.sympify(e)) for sym, e in temps], [sp.sympify(e) for e in reduced]


def _cse_sympy(exprs, rename):
    sub = {s: sp.Symbol(new) for s, new in rename.items()}
    plain = [sp.sympify(e).xreplace(sub) for e in exprs]
    temps, reduced = sp.cse(plain, symbols=sp.numbered_symbols("x"), order="canonical")
    return [(str(sym), e) for sym, e in temps], list(reduced)

