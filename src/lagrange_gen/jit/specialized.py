"""Specialized glue: a generated module's ``run_<method>`` and ``ensemble_<method>``, owned by
the library.

A generated module holds its kernels and metadata only. The glue that runs a method on it (the
method's stepping loop with the module's kernels compiled in, numba ``cache=True``;
codegen/glue.py) is written here on first use, from the module's metadata: the generated
module's ``__getattr__`` (PEP 562) calls glue_attribute, which writes the glue file of the
method (atomically, once), imports it and hands out the function asked for.

The file lives beside the portable glue, in the method's library-version directory
(portable.library_hash: the package files the glue compiles and the text that writes it), and
its name carries the generated module's import name and KEY: a regenerated model or a changed
stepper gets a new file, compiled by numba once; an unchanged pair finds its compiled code in
numba's cache (keyed on the file). When a module's KEY changes, the files and numba cache
entries of its earlier KEY in that directory are removed.
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

from . import folders, portable

#: The attributes of a generated module that are its glue: prefix + a method of its METHODS.
GLUE_PREFIXES = ("run_", "ensemble_", "_member_", "_loop_")

#: Hex digits of a module's KEY in its glue file's name.
KEY_DIGITS = 16


def method_of(module, name):
    """The method whose glue defines ``name`` on ``module`` (a method of module.METHODS), or
    None when ``name`` is not a glue attribute of that module."""
    methods = getattr(module, "METHODS", ())
    for prefix in GLUE_PREFIXES:
        if name.startswith(prefix) and name[len(prefix):] in methods:
            return name[len(prefix):]
    return None


def glue_attribute(module_name, name):
    """Attribute ``name`` of the generated module ``module_name`` (in sys.modules) that is its
    glue: the function from the glue file of its method (written and imported on first use, then
    kept in the module's namespace, so later lookups do not come here). AttributeError, as for
    any missing attribute, when ``name`` is no glue of that module (an ensemble of an adaptive
    method, a method the module was not generated for)."""
    module = sys.modules.get(module_name)
    method = None if module is None else method_of(module, name)
    value = None if method is None else getattr(glue_module(module, method), name, None)
    if value is None:
        raise AttributeError(f"module {module_name!r} has no attribute {name!r}")
    setattr(module, name, value)
    return value


def glue_file_stem(module) -> str:
    """The glue file's name without ``.py``: the module's import name made an identifier, then
    KEY_DIGITS of its KEY."""
    tag = re.sub(r"\W", "_", module.__name__)
    return f"{tag}_{module.KEY[:KEY_DIGITS]}"


def glue_module(module, method):
    """The imported glue file of ``method`` for the generated ``module`` (written if missing;
    one per process). A cache folder that cannot be written is replaced as the portable glue's
    is (folders.write_in_version)."""
    glues = module.__dict__.setdefault("_SPECIALIZED_GLUE", {})
    if method in glues:
        return glues[method]
    from ..codegen.glue import specialized_glue_source
    digest = portable.library_hash(method)
    source = specialized_glue_source(method, module.__name__, module.KEY, digest,
                                     portable.n_saved(module, method), module.N_EVENTS)
    stem = glue_file_stem(module)
    path = folders.write_in_version(digest, f"{stem}.py", source)
    remove_earlier_keys(path.parent, stem)
    name = f"lagrange_gen_specialized_{digest}_{stem}"
    glue = sys.modules.get(name)
    if glue is None:
        glue = folders.import_file(name, path)
    glues[method] = glue
    return glue


def remove_earlier_keys(folder: Path, stem: str) -> list:
    """Remove the glue files in ``folder`` of the module whose glue file is ``stem``.py under
    another KEY (same name up to the KEY's digits), and their numba cache entries in the
    folder's __pycache__; returns the paths removed. A process still running an old glue keeps
    what it loaded (a failed cache save is a miss, lagrange_gen.jit)."""
    prefix = stem[:-KEY_DIGITS]
    pattern = re.compile(re.escape(prefix) + r"[0-9a-f]{%d}\." % KEY_DIGITS)
    removed = []
    for directory in (folder, folder / "__pycache__"):
        try:
            entries = list(directory.iterdir())
        except OSError:
            continue
        for entry in entries:
            if pattern.match(entry.name) and not entry.name.startswith(stem + "."):
                try:
                    entry.unlink()
                    removed.append(entry)
                except OSError:
                    pass
    return removed
