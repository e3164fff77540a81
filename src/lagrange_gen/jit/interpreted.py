"""The interpreted tier: the stepper library run as plain Python, for a first run that numba has
not compiled yet.

A first simulate after an install waits for numba to compile the portable glue of its method
(seconds to tens of seconds, jit/portable.py), most of it type inference and LLVM, for a run that
may be ten steps. The interpreted tier runs the very same code without compiling it: every numba
dispatcher keeps the Python function it was made from (``py_func``), and ``twin(dispatcher)``
returns that function re-bound so that everything it calls is a twin too. A Python twin of the
portable glue's ``run_<method>`` then runs run_loop, the method's prepare and step, Newton, the
linear algebra and the model's kernels as Python, on the same arrays, in the same order of
operations: the results equal the compiled run's to round-off (tests/test_interpreted.py checks
every fixed-step method). One place still knows each method.

How the re-binding works (all lazy and memoized, so only what a run reaches is twinned):

- a function's twin has the same code, defaults, closure (cells re-made with twinned contents)
  and attributes; its globals are a ``_TwinGlobals`` dict of its module, which answers a name the
  first time it is looked up with the twin of the module's value;
- a dispatcher's twin is the twin of its ``py_func``; a CalleeDispatcher (jit/callee.py) is a
  dispatcher like any other here;
- a module of the package, a generated module or a portable glue module (a name starting with
  ``lagrange_gen``; the stepper library passes modules as values: ``method``, ``kern``, Newton's
  problem modules) becomes a module whose attributes are twins, looked up on first use;
- a tuple (a named tuple of kernels, a kernel table) is rebuilt with twinned items; a portable
  kernel table's first-class functions (portable.FunctionKernel) become their dispatcher's twin;
- anything else (numpy, math, arrays, numbers, classes) is itself.

What has no Python meaning, in one place: numba's compile-time options (``inline=`` cost models,
``cache``, ``error_model``, ``_nrt``, the wrapper options of jit.callee) only change how code is
compiled and are ignored. numba's numpy error model turns a division by zero or a math domain
error into inf/NaN, which the run loop reports as NON_FINITE; Python raises instead
(ZeroDivisionError on Python floats, ValueError from math.sqrt or math.log of a bad argument):
``run`` turns such an exception into PYTHON_ONLY_FAILURE so that the caller runs the same steps
compiled (run/fixed_driver.py does). numpy's own floating-point warnings are silenced, as numba
gives none. The stepper library uses no ``@overload``, ``literal_unroll``, ``prange`` or typed
signatures on the fixed-step path; a construct that needs numba (one that raises TypeError or
NotImplementedError when run as Python) is reported the same way, not guessed at.
"""

from __future__ import annotations

import types

import numpy as np

#: What ``run`` returns instead of the glue's (status, steps, n_events) when the Python twin
#: raised where the compiled code would not (module docstring): the caller runs the chunk
#: compiled.
PYTHON_ONLY_FAILURE = None

#: Exceptions a Python twin may raise where numba's compiled code gives inf/NaN or needs a
#: numba construct (module docstring).
_PYTHON_ONLY = (ArithmeticError, ValueError, TypeError, NotImplementedError)

#: Prefix of the modules whose attributes are twinned: the package, generated modules
#: (lagrange_gen_generated_...) and portable glue modules (lagrange_gen_portable_...).
TWINNED_PREFIX = "lagrange_gen"

#: {id(original): (original, twin)}: every twin made in this process (the original is kept so
#: that its id is not reused).
_TWINS: dict = {}


def _dispatcher_class():
    from numba.core.dispatcher import Dispatcher
    return Dispatcher


def twin(value):
    """The Python twin of ``value`` (module docstring): a dispatcher's or a package function's
    twin function, a package module's twin module, a tuple with twinned items, else ``value``."""
    entry = _TWINS.get(id(value))
    if entry is not None and entry[0] is value:
        return entry[1]
    made = _make_twin(value)
    if made is not value:
        _TWINS[id(value)] = (value, made)
    return made


def _make_twin(value):
    if isinstance(value, _dispatcher_class()):
        return twin(value.py_func)
    if isinstance(value, types.FunctionType):
        return _twin_function(value) if _twinned_name(value.__module__) else value
    if isinstance(value, types.ModuleType):
        return _twin_module(value) if _twinned_name(value.__name__) else value
    if isinstance(value, tuple):
        items = tuple(twin(item) for item in value)
        if all(a is b for a, b in zip(items, value)):
            return value
        return type(value)(*items) if hasattr(value, "_fields") else items
    dispatcher = getattr(value, "dispatcher", None)      # portable.FunctionKernel
    if dispatcher is not None and hasattr(value, "__wrapper_address__"):
        return twin(dispatcher)
    return value


def _twinned_name(name) -> bool:
    return isinstance(name, str) and name.startswith(TWINNED_PREFIX)


class _TwinGlobals(dict):
    """The globals of the twins of one module's functions: a name is looked up in the module's
    own globals the first time and its twin kept (CPython looks a function's globals up through
    __getitem__ when they are not exactly a dict, so __missing__ is asked on a first use)."""

    def __init__(self, original):
        super().__init__()
        self.original = original
        self["__builtins__"] = original.get("__builtins__", __builtins__)
        self["__name__"] = original.get("__name__")

    def __missing__(self, name):
        value = twin(self.original[name])          # KeyError: then CPython tries builtins
        self[name] = value
        return value


#: {id(module globals): (globals, their _TwinGlobals)}
_GLOBALS: dict = {}


def _twin_globals(original):
    entry = _GLOBALS.get(id(original))
    if entry is None or entry[0] is not original:
        entry = _GLOBALS[id(original)] = (original, _TwinGlobals(original))
    return entry[1]


def _twin_function(fn):
    closure = None
    if fn.__closure__:
        closure = tuple(_twin_cell(cell) for cell in fn.__closure__)
    made = types.FunctionType(fn.__code__, _twin_globals(fn.__globals__), fn.__name__,
                              fn.__defaults__, closure)
    made.__kwdefaults__ = fn.__kwdefaults__
    made.__qualname__, made.__module__ = fn.__qualname__, fn.__module__
    made.__doc__ = fn.__doc__
    made.__dict__.update(fn.__dict__)
    made.python_twin_of = fn
    return made


def _twin_cell(cell):
    try:
        contents = cell.cell_contents
    except ValueError:                 # an empty cell (a name not yet bound in its scope)
        return types.CellType()
    return types.CellType(twin(contents))


def _twin_module(module):
    """A module named like ``module`` whose attributes are twins of ``module``'s, looked up on
    first use (a module-level __getattr__, PEP 562)."""
    names = _twin_globals(module.__dict__)
    made = types.ModuleType(module.__name__, module.__doc__)

    def __getattr__(name):
        try:
            value = names[name]
        except KeyError:
            raise AttributeError(f"module {module.__name__!r} has no attribute {name!r}") from None
        setattr(made, name, value)
        return value

    made.__getattr__ = __getattr__
    made.python_twin_of = module
    return made


def run(glue_twin, *args):
    """``glue_twin(*args)`` (the twin of a glue's run_<method>) with numpy's floating-point
    warnings off; PYTHON_ONLY_FAILURE when it raised one of the exceptions that have no
    counterpart in the compiled code (module docstring)."""
    with np.errstate(all="ignore"):
        try:
            return glue_twin(*args)
        except _PYTHON_ONLY:
            return PYTHON_ONLY_FAILURE


def runner(glue, kern, *bound):
    """A callable with the glue arguments that runs the Python twin of the dispatcher ``glue``
    (a portable glue's run_<method>) on ``kern`` (a generated module, passed as its twin) with
    ``bound`` (the portable glue's n_saved) in front; it returns PYTHON_ONLY_FAILURE (None)
    where the compiled glue would return (status, steps, n_events) but Python cannot run on."""
    glue_twin, kern_twin = twin(glue), twin(kern)

    def interpreted(*args):
        return run(glue_twin, kern_twin, *bound, *args)

    return interpreted

