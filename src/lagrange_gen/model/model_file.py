"""Running a model file: execute it, pick its Model, and turn whatever the file does wrong
(exceptions, sys.exit, os.chdir) into one ModelError line naming the file and line."""

from __future__ import annotations

import os
import runpy
import traceback
from pathlib import Path

from ..errors import ModelError
from .data_files import file_record, files_read
from .model import Model

__all__ = ["load_model"]


def load_model(path, **options) -> Model:
    """Execute a model file and return its validated Model.

    With ``options`` the file must define ``build(**options)`` (e.g. ``n=8`` for the n-link
    pendulum); otherwise it assigns a Model to ``model`` or, failing that, defines a ``build()``
    whose defaults give the model. Every failure is a ModelError whose
    message names the file.
    """
    path = Path(path)
    if not path.is_file():
        raise ModelError(f"{path}: no such model file")
    if path.suffix != ".py":
        raise ModelError(f"{path}: a model file must be a Python file ending in .py")
    try:
        source = path.read_text()
    except (OSError, UnicodeDecodeError) as exc:
        raise ModelError(f"{path}: cannot read: {exc}") from None
    try:
        compile(source, str(path), "exec")
    except SyntaxError as exc:
        raise ModelError(f"{path}:{exc.lineno}: not valid Python: {exc.msg}") from None
    with files_read(exclude=[path]) as data_files:
        model = _run_model_file(path, options)
    model.source_path = str(path)
    # What the model read besides its own text: generation records it (codegen.generate).
    model.data_files = {name: file_record(name) for name in sorted(data_files)}
    model.source_text = source
    model.build_options = dict(options)
    return model


def _run_model_file(path, options):
    """Run the file and pick its Model; every failure (an exception, sys.exit, any other
    BaseException but Ctrl-C) becomes a ModelError naming the file and line. The path is resolved
    before and the working directory restored after, whatever the file does (os.chdir)."""
    resolved, cwd = path.resolve(), os.getcwd()
    try:
        namespace = runpy.run_path(str(resolved), run_name=f"lagrange_gen_model_{path.stem}")
        return _pick_model(path, namespace, options)
    except ModelError as exc:
        msg = str(exc)
        raise ModelError(msg if msg.startswith(str(path)) else f"{path}: {msg}") from None
    except KeyboardInterrupt:   # the user pressed Ctrl-C: the CLI reports "interrupted"
        raise
    except SystemExit as exc:
        line = _user_line(exc, resolved)
        raise ModelError(f"{path}{line}: exited while loading (SystemExit: {exc.code}); a model file "
                         "must define `model`, not exit") from None
    except BaseException as exc:  # the user's code raised: report file and line, not a traceback
        line = _user_line(exc, resolved)
        raise ModelError(f"{path}{line}: raised {type(exc).__name__}: {exc}") from exc
    finally:
        os.chdir(cwd)


def _pick_model(path, namespace, options):
    if options:
        build = namespace.get("build")
        if not callable(build):
            raise ModelError(f"{path}: options {options} given but the file defines no build(**options)")
        model = build(**options)
    else:
        model = namespace.get("model")
        if model is None:
            found = {}          # id -> first name: one Model under two names counts once
            for name, value in namespace.items():
                if isinstance(value, Model):
                    found.setdefault(id(value), (name, value))
            if len(found) > 1:
                names = ", ".join(name for name, _ in found.values())
                raise ModelError(f"{path}: defines {len(found)} Models ({names}) and none is named "
                                 "`model`: assign the one to generate to `model`")
            if found:
                model = next(iter(found.values()))[1]
            elif callable(namespace.get("build")):
                model = _build_with_defaults(path, namespace["build"])
    if not isinstance(model, Model):
        raise ModelError(f"{path}: defines no Model (assign one to a variable named `model`)")
    return model


def _build_with_defaults(path, build):
    """build() of a file that defines no Model: its defaults must give one."""
    import inspect
    try:
        required = [name for name, par in inspect.signature(build).parameters.items()
                    if par.default is par.empty and par.kind in (par.POSITIONAL_OR_KEYWORD,
                                                                  par.KEYWORD_ONLY)]
    except (TypeError, ValueError):
        required = []
    if required:
        raise ModelError(f"{path}: defines no `model`, and build() needs {', '.join(required)}: "
                         f"give them, e.g. --set {required[0]}=...")
    return build()


def _user_line(exc, resolved):
    """":LINE" of the innermost frame of the exception in the (resolved) model file, or ""."""
    for frame in reversed(traceback.extract_tb(exc.__traceback__)):
        if Path(frame.filename) == resolved:
            return f":{frame.lineno}"
    return ""
