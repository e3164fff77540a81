"""A content key of a user's jitted function: what its compiled code is made of.

numba's cache recognizes a function by its source file's name and time stamp only, and freezes
the global values it reads into the code (a gain set at run time, another jitted function it
calls in another file: neither is checked). A controller's input hook is cached under this key
instead (run/controller_hooks.py), so the key must change whenever the compiled code could: it
hashes the function's bytecode and constants (nested functions too), the values of its closure
cells, defaults and the globals it reads, and the numba options it was jitted with; a jitted
function it calls is keyed the same way, recursively.

A value the key cannot vouch for (a list, a dict, a user object, a module other than numpy,
math, cmath, numba and scipy, whose attributes the key does not follow) makes the function
uncacheable: ``content_key`` returns None and the caller compiles it in each process, as
numba does for code it cannot cache.
"""

from __future__ import annotations

import builtins
import hashlib
import types

import numpy as np

#: Top-level packages whose modules a keyed function may read attributes of: their contents
#: change only with their version, which numba's own cache index checks.
STABLE_PACKAGES = frozenset({"numpy", "math", "cmath", "numba", "scipy", "operator"})


class _Uncacheable(Exception):
    """A value that content_key cannot hash faithfully."""


def content_key(dispatcher) -> str | None:
    """sha256 hex digest of everything numba compiles ``dispatcher`` (a numba Dispatcher) from
    (module docstring), or None when it reads something the key cannot vouch for."""
    digest = hashlib.sha256()
    try:
        _add_dispatcher(dispatcher, digest, set())
    except _Uncacheable:
        return None
    return digest.hexdigest()


def _is_dispatcher(value) -> bool:
    return hasattr(value, "py_func") and hasattr(value, "targetoptions")


def _add_dispatcher(dispatcher, digest, seen):
    func = dispatcher.py_func
    if id(func) in seen:              # recursion between jitted functions: keyed once
        digest.update(b"seen:" + func.__qualname__.encode())
        return
    seen.add(id(func))
    digest.update(b"options:" + repr(sorted((k, repr(v)) for k, v in dispatcher.targetoptions.items())).encode())
    _add_function(func, digest, seen)


def _add_function(func, digest, seen):
    if not isinstance(func, types.FunctionType):
        raise _Uncacheable
    code = func.__code__
    names = _add_code(code, digest)
    for cell in func.__closure__ or ():
        try:
            contents = cell.cell_contents
        except ValueError:            # an empty cell (a name bound later): nothing to freeze
            raise _Uncacheable from None
        _add_value(contents, digest, seen)
    for default in func.__defaults__ or ():
        _add_value(default, digest, seen)
    namespace = func.__globals__
    for name in sorted(names):
        digest.update(b"name:" + name.encode())
        if name in namespace:
            _add_value(namespace[name], digest, seen)
        elif hasattr(builtins, name):
            digest.update(b"builtin")
        # else: an attribute name (np.sin reads "np", then "sin"), keyed by the bytecode


def _add_code(code, digest) -> set:
    """Hash a code object and the code objects among its constants; returns every name they
    read (globals and attributes)."""
    digest.update(code.co_code)
    digest.update(repr((code.co_argcount, code.co_kwonlyargcount, code.co_flags, code.co_varnames,
                        code.co_freevars, code.co_names)).encode())
    names = set(code.co_names)
    for const in code.co_consts:
        if isinstance(const, types.CodeType):
            names |= _add_code(const, digest)
        else:
            digest.update(b"const:" + type(const).__name__.encode() + repr(const).encode())
    return names


def _add_value(value, digest, seen):
    if value is None or isinstance(value, (bool, int, float, complex, str, bytes)):
        digest.update(f"{type(value).__name__}:{value!r}".encode())
    elif isinstance(value, np.ndarray):
        if value.dtype.hasobject:
            raise _Uncacheable
        digest.update(f"array:{value.dtype.str}:{value.shape}".encode())
        digest.update(np.ascontiguousarray(value).tobytes())
    elif isinstance(value, np.generic):
        digest.update(f"scalar:{value.dtype.str}:{value!r}".encode())
    elif isinstance(value, tuple):
        digest.update(f"tuple:{len(value)}".encode())
        for item in value:
            _add_value(item, digest, seen)
    elif isinstance(value, types.ModuleType):
        if value.__name__.split(".")[0] not in STABLE_PACKAGES:
            raise _Uncacheable
        digest.update(b"module:" + value.__name__.encode())
    elif _is_dispatcher(value):
        _add_dispatcher(value, digest, seen)
    elif _from_stable_package(value):
        digest.update(f"object:{type(value).__module__}:{getattr(value, '__qualname__', repr(value))}".encode())
    else:
        raise _Uncacheable


def _from_stable_package(value) -> bool:
    """A function, ufunc, class or numba type defined by a STABLE_PACKAGES module (np.sin, a
    `from math import sqrt`, numba's float64), or a builtin function."""
    if isinstance(value, types.BuiltinFunctionType) and value.__module__ in (None, "builtins"):
        return True
    module = getattr(value, "__module__", None) if isinstance(value, (type, types.BuiltinFunctionType,
                                                                       types.FunctionType, np.ufunc)) \
        else type(value).__module__
    return isinstance(module, str) and module.split(".")[0] in STABLE_PACKAGES
