"""The compiled hooks of a jitted controller, kept across processes.

A controller u = f(t, q, qd, p) runs inside the stepping loop through its input hook
``apply(c, t, q, v, p) -> changed`` (run/control.py), and the run first asks it, through
``probe``, for its value at the initial state (size and finiteness checked before the loop
writes it unchecked). Both are compiled with the controller inlined. numba cannot cache a
function written around another one at run time, so both used to be compiled again in every
process, with the controller.

Here they are the functions of a small file written in the cache folder
(folders.write_in_version), named after the controller's content key (jit/function_key.py):
numba caches them like any file, so a new process running a controller it ran before loads
both and compiles nothing. The controller is a global of that file, set after import and read
only when numba compiles (the first time for that content). A controller whose key cannot be
formed (it reads a list, a dict, an object of the user's) gets the same functions from the same
text, compiled in this process only.
"""

from __future__ import annotations

import hashlib
import sys
from dataclasses import dataclass

from ..jit import folders
from ..jit.function_key import content_key

#: The hooks' text; {cache} is True for the file in the cache folder, False for the in-process
#: twin; {args} the controller's arguments.
HOOK_SOURCE = '''"""Input hooks of one controller (lagrange_gen.run.controller_hooks): written by the library."""
import numpy as np

from lagrange_gen.jit import njit
from lagrange_gen.run.control import _write_inputs, _value_into

controller = None        # the user's jitted controller, set before the first compile


# An exception raised by the controller cannot leave a hook called through a pointer (numba
# prints it and goes on): the hook writes NaN into the last input instead, which ends the run at
# that step with one line naming the controller (control.blame_inputs).
@njit(cache={cache}, error_model="numpy")
def apply(c, t, q, v, p):
    try:
        return _write_inputs(controller({args}), p)
    except Exception:
        p[p.shape[0] - 1] = np.nan
        return True


@njit(cache={cache}, error_model="numpy")
def probe(c, t, q, v, p, out):
    """(ndim, size) of the controller's value at (t, q, v), its first entries written to out."""
    return _value_into(controller({args}), out)
'''


@dataclass(frozen=True)
class ControllerHooks:
    """apply(c, t, q, v, p) -> changed and probe(c, t, q, v, p, out) -> (ndim, size) of one
    controller; ``cached``: whether they live in a file numba caches (else this process only)."""
    apply: object
    probe: object
    cached: bool


def hook_source(with_params: bool, cache: bool) -> str:
    """HOOK_SOURCE for a controller f(t, q, qd, p) or, with_params, f(t, q, qd, p, c)."""
    return HOOK_SOURCE.format(cache=cache, args="t, q, v, p, c" if with_params else "t, q, v, p")


def hooks_version() -> str:
    """sha256 prefix of the package files the hooks compile (control.py and what it imports)
    and of this file: the library version directory of the hook files."""
    from ..jit.sources import source_closure, source_hashes
    files = source_closure(["run.control", "run.controller_hooks"])
    return hashlib.sha256(repr(sorted(source_hashes(files).items())).encode()).hexdigest()[:16]


def controller_hooks(controller, with_params: bool) -> ControllerHooks:
    """The hooks of ``controller`` (a numba dispatcher): from the cache folder's file of its
    content key, or compiled in this process when it has none (module docstring)."""
    key = content_key(controller)
    if key is None:
        namespace = {"__name__": f"lagrange_gen_hooks_of_{controller.__name__}"}
        exec(compile(hook_source(with_params, cache=False), f"<input hooks of {controller.__name__}>",  # noqa: S102
                     "exec"), namespace)
        namespace["controller"] = controller
        return ControllerHooks(namespace["apply"], namespace["probe"], cached=False)
    stem = f"hook_{hashlib.sha256((key + str(with_params)).encode()).hexdigest()[:20]}"
    version = hooks_version()
    name = f"lagrange_gen_hooks_{version}_{stem}"
    module = sys.modules.get(name)
    if module is None:
        path = folders.write_in_version(version, f"{stem}.py", hook_source(with_params, cache=True))
        module = folders.import_file(name, path)
        module.controller = controller
    return ControllerHooks(module.apply, module.probe, cached=True)
