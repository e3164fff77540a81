"""Calls of native kernels from Python: compiled once per installation, not per model.

A generated kernel called from Python (``accelerations``, the energy check after a run,
``linearize``) would be compiled by numba for its model on the first call. Its native twin
(jit/native.py) is compiled already; what remains is to call it. ctypes would do, at tens of
microseconds a call (each array's address through ``ndarray.ctypes``); numba's dispatcher does
it in about a microsecond. So the call goes through a small jitted function of this module,
``call_<kind>_<n>(address, a0, ..., a<n-1>)`` (n the kernel's arguments, kind what it returns),
that numba compiles once per set of argument types (a handful: every kernel takes float64
arrays and a float t) and keeps in its disk cache: the kernel's address is a plain integer
argument, and ``_call_address`` (an intrinsic) calls it with numba's own array structures, the
ABI of the native kernel's exported function. The arguments are passed one by one, not as a
tuple: numba types a tuple argument in Python, several microseconds a call.

Shapes: the kernel's arguments, C-contiguous float64 arrays and a float t (jit.python_calls
has checked them).
"""

from __future__ import annotations

from numba import types
from numba.extending import intrinsic
from llvmlite import ir

from .cache import njit

_RETURN = {0: types.none, 1: types.float64, 2: types.int64, 3: types.boolean}


@intrinsic
def _call_address(typingctx, address, ret_code, *args):
    """Call the function at ``address`` (int64) with ``args`` passed as numba passes them to a
    C wrapper (their value types, arrays by value); ``ret_code`` a literal: 0 nothing (the
    function returns a null i8*), 1 float64, 2 int64, 3 bool."""
    if not isinstance(ret_code, types.IntegerLiteral):
        return None
    arg_types = args[0].types if len(args) == 1 and isinstance(args[0], types.StarArgTuple) \
        else tuple(args)
    restype = _RETURN[ret_code.literal_value]
    sig = restype(address, ret_code, types.StarArgTuple.from_types(arg_types))

    def codegen(context, builder, signature, llargs):
        addr, _, packed = llargs
        items = [builder.extract_value(packed, i) for i in range(len(arg_types))]
        ll_ret = context.get_value_type(types.voidptr if restype is types.none else restype)
        fnty = ir.FunctionType(ll_ret, [context.get_value_type(t) for t in arg_types])
        result = builder.call(builder.inttoptr(addr, fnty.as_pointer()), items)
        if restype is types.none:
            return context.get_dummy_value()
        return result

    return sig, codegen


@njit(cache=True)
def call_none_4(address, a0, a1, a2, a3):
    """A native kernel of 4 arguments returning nothing."""
    _call_address(address, 0, a0, a1, a2, a3)


@njit(cache=True)
def call_none_5(address, a0, a1, a2, a3, a4):
    """A native kernel of 5 arguments returning nothing."""
    _call_address(address, 0, a0, a1, a2, a3, a4)


@njit(cache=True)
def call_none_6(address, a0, a1, a2, a3, a4, a5):
    """A native kernel of 6 arguments returning nothing."""
    _call_address(address, 0, a0, a1, a2, a3, a4, a5)


@njit(cache=True)
def call_none_7(address, a0, a1, a2, a3, a4, a5, a6):
    """A native kernel of 7 arguments returning nothing."""
    _call_address(address, 0, a0, a1, a2, a3, a4, a5, a6)


@njit(cache=True)
def call_none_9(address, a0, a1, a2, a3, a4, a5, a6, a7, a8):
    """A native kernel of 9 arguments returning nothing."""
    _call_address(address, 0, a0, a1, a2, a3, a4, a5, a6, a7, a8)


@njit(cache=True)
def call_none_11(address, a0, a1, a2, a3, a4, a5, a6, a7, a8, a9, a10):
    """A native kernel of 11 arguments returning nothing."""
    _call_address(address, 0, a0, a1, a2, a3, a4, a5, a6, a7, a8, a9, a10)


@njit(cache=True)
def call_float_4(address, a0, a1, a2, a3):
    """A native kernel of 4 arguments returning a float (energy)."""
    return _call_address(address, 1, a0, a1, a2, a3)


@njit(cache=True)
def call_float_5(address, a0, a1, a2, a3, a4):
    """A native kernel of 5 arguments returning a float (energy)."""
    return _call_address(address, 1, a0, a1, a2, a3, a4)


@njit(cache=True)
def call_float_6(address, a0, a1, a2, a3, a4, a5):
    """A native kernel of 6 arguments returning a float (energy)."""
    return _call_address(address, 1, a0, a1, a2, a3, a4, a5)


@njit(cache=True)
def call_float_7(address, a0, a1, a2, a3, a4, a5, a6):
    """A native kernel of 7 arguments returning a float (energy)."""
    return _call_address(address, 1, a0, a1, a2, a3, a4, a5, a6)


@njit(cache=True)
def call_float_9(address, a0, a1, a2, a3, a4, a5, a6, a7, a8):
    """A native kernel of 9 arguments returning a float (energy)."""
    return _call_address(address, 1, a0, a1, a2, a3, a4, a5, a6, a7, a8)


@njit(cache=True)
def call_float_11(address, a0, a1, a2, a3, a4, a5, a6, a7, a8, a9, a10):
    """A native kernel of 11 arguments returning a float (energy)."""
    return _call_address(address, 1, a0, a1, a2, a3, a4, a5, a6, a7, a8, a9, a10)


@njit(cache=True)
def call_int_4(address, a0, a1, a2, a3):
    """A native kernel of 4 arguments returning an int (a status)."""
    return _call_address(address, 2, a0, a1, a2, a3)


@njit(cache=True)
def call_int_5(address, a0, a1, a2, a3, a4):
    """A native kernel of 5 arguments returning an int (a status)."""
    return _call_address(address, 2, a0, a1, a2, a3, a4)


@njit(cache=True)
def call_int_6(address, a0, a1, a2, a3, a4, a5):
    """A native kernel of 6 arguments returning an int (a status)."""
    return _call_address(address, 2, a0, a1, a2, a3, a4, a5)


@njit(cache=True)
def call_int_7(address, a0, a1, a2, a3, a4, a5, a6):
    """A native kernel of 7 arguments returning an int (a status)."""
    return _call_address(address, 2, a0, a1, a2, a3, a4, a5, a6)


@njit(cache=True)
def call_int_9(address, a0, a1, a2, a3, a4, a5, a6, a7, a8):
    """A native kernel of 9 arguments returning an int (a status)."""
    return _call_address(address, 2, a0, a1, a2, a3, a4, a5, a6, a7, a8)


@njit(cache=True)
def call_int_11(address, a0, a1, a2, a3, a4, a5, a6, a7, a8, a9, a10):
    """A native kernel of 11 arguments returning an int (a status)."""
    return _call_address(address, 2, a0, a1, a2, a3, a4, a5, a6, a7, a8, a9, a10)


@njit(cache=True)
def call_bool_4(address, a0, a1, a2, a3):
    """A native kernel of 4 arguments returning a bool."""
    return _call_address(address, 3, a0, a1, a2, a3)


@njit(cache=True)
def call_bool_5(address, a0, a1, a2, a3, a4):
    """A native kernel of 5 arguments returning a bool."""
    return _call_address(address, 3, a0, a1, a2, a3, a4)


@njit(cache=True)
def call_bool_6(address, a0, a1, a2, a3, a4, a5):
    """A native kernel of 6 arguments returning a bool."""
    return _call_address(address, 3, a0, a1, a2, a3, a4, a5)


@njit(cache=True)
def call_bool_7(address, a0, a1, a2, a3, a4, a5, a6):
    """A native kernel of 7 arguments returning a bool."""
    return _call_address(address, 3, a0, a1, a2, a3, a4, a5, a6)


@njit(cache=True)
def call_bool_9(address, a0, a1, a2, a3, a4, a5, a6, a7, a8):
    """A native kernel of 9 arguments returning a bool."""
    return _call_address(address, 3, a0, a1, a2, a3, a4, a5, a6, a7, a8)


@njit(cache=True)
def call_bool_11(address, a0, a1, a2, a3, a4, a5, a6, a7, a8, a9, a10):
    """A native kernel of 11 arguments returning a bool."""
    return _call_address(address, 3, a0, a1, a2, a3, a4, a5, a6, a7, a8, a9, a10)

#: The caller of a kernel by (return kind (native_ir: None, "f", "i", "b"), number of arguments).
CALLERS = {(kind, n): globals()[f"call_{name}_{n}"]
           for kind, name in ((None, "none"), ("f", "float"), ("i", "int"), ("b", "bool"))
           for n in (4, 5, 6, 7, 9, 11)}
