"""Make numba type ``a * b`` on two float64 once per process, not once per occurrence.

numba's type inference resolves every call in a function through its templates
(numba.core.types.functions.BaseFunction.get_call_type): for ``operator.mul`` on two float64 it
tries a dozen templates (integers, complex, NumPy ufuncs, ...) until one accepts, and it does so
again for each of the thousands of multiplications of a generated kernel. Nothing is kept
between two occurrences. In a profile (cProfile, 16-link pendulum, momentum_rate_jacobian with
the mass_matvec_dq it calls) type inference takes about two thirds of the compile, over ten
template applications per call.

``install()`` wraps ``BaseFunction.get_call_type`` with a memo for the calls whose arguments
are all plain numeric scalars (Float, Integer, Boolean, not literals) and that have no keyword
arguments: arithmetic, comparisons and ``math`` functions on floats, what the generated kernels
are made of. Their signature depends only on the function and those types. A hit returns the
signature found the first time and records the implementation key numba's lowering looks up
(``_impl_keys``), as the first resolution did. Every other call goes through numba unchanged.

Nearly every such call of a large kernel is then a hit, and the kernels compile to the same
machine code (tests/test_numba_typing_memo.py compares the assembly of every kernel of two
models with and without the memo) in about three quarters of the time (kernels with and without
it: ``lagrange-gen bench compile``, reports/compile.md). The stepper glue hardly gains: its
calls take arrays.

Active only while a lagrange_gen function compiles (jit.speedups.compiling), when
$LAGRANGE_GEN_SPEEDUPS selects typing_memo and numba's get_call_type still records the
implementation key as the memo expects (``unsupported``).
"""

from __future__ import annotations

import inspect

#: The statement of numba's get_call_type the memo stands for: a resolution records the
#: template's implementation key, which the lowering looks up.
_EXPECTED = "self._impl_keys[sig.args] = temp.get_impl_key(sig)"

_state = {"hits": 0, "misses": 0}
#: {(typing context, function type, argument types): (signature, implementation key)}: kept
#: between compiles (the function types and contexts are numba's, alive for the process).
_memo: dict = {}


def unsupported():
    """None when numba's BaseFunction.get_call_type is as the memo expects, else why not."""
    from numba.core import types
    from numba.core.types.functions import BaseFunction
    original = BaseFunction.get_call_type
    if _EXPECTED not in inspect.getsource(original):
        return "numba's BaseFunction.get_call_type no longer records _impl_keys as expected"
    if not all(hasattr(types, n) for n in ("Float", "Integer", "Boolean", "Literal")):
        return "numba.core.types lacks a scalar type class"
    return None


def activate():
    """Wrap numba's BaseFunction.get_call_type with the memo; returns the undo."""
    from numba.core import types
    from numba.core.types.functions import BaseFunction
    original = BaseFunction.__dict__["get_call_type"]
    plain = (types.Float, types.Integer, types.Boolean)
    literal = types.Literal
    memo = _memo

    def get_call_type(self, context, args, kws):
        if kws or not all(isinstance(a, plain) and not isinstance(a, literal) for a in args):
            return original(self, context, args, kws)
        key = (context, self, args)
        found = memo.get(key)
        if found is not None:
            _state["hits"] += 1
            sig, impl_key = found
            self._impl_keys[sig.args] = impl_key
            return sig
        _state["misses"] += 1
        sig = original(self, context, args, kws)
        if sig is not None and sig.args in self._impl_keys:
            memo[key] = (sig, self._impl_keys[sig.args])
        return sig

    get_call_type.__wrapped__ = original
    BaseFunction.get_call_type = get_call_type

    def restore():
        BaseFunction.get_call_type = original

    return restore


def stats() -> dict:
    """{"hits": int, "misses": int} of the memo in this process."""
    return dict(_state)
