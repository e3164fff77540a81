"""What every subcommand parses alike: NAME=VALUE lists (--param, --freeze, --set), times and
ranges START:STOP:STEP (--t-eval), method names (--method), velocity names (--keep), the folder of generated modules (-o, --gen-dir), and warnings turned into one
``lagrange-gen: warning: ...`` line each."""

from __future__ import annotations

import contextlib
import math
import sys
import warnings

from ..errors import LagrangeGenError

#: How each option converts its values: numbers are finite floats; build options int, float or
#: the text itself (a build() may take a name).
NUMBER, BUILD = "number", "build"


def parse_assignments(values, option, kind=NUMBER, error=LagrangeGenError):
    """``['a=1,b=2', 'c=3']`` (an append option; a single string too) -> {'a': 1.0, 'b': 2.0,
    'c': 3.0}. ``kind`` NUMBER: finite floats; BUILD: int, else float, else the text. A malformed
    item is ``error`` naming ``option`` and the item."""
    if values is None:
        return {}
    if isinstance(values, str):
        values = [values]
    out = {}
    for text in values:
        for item in text.split(","):
            if not item.strip():
                continue
            name, sep, value = item.partition("=")
            name = name.strip()
            if not sep or not name.isidentifier():
                raise error(f"{option} {item.strip()}: expected NAME=VALUE, e.g. {option} a=1,b=2")
            out[name] = _convert(name, value.strip(), kind, option, item.strip(), error)
    return out


def _convert(name, value, kind, option, item, error):
    if kind == BUILD:
        for convert in (int, float):
            try:
                return convert(value)
            except ValueError:
                continue
        return value
    try:
        number = float(value)
    except ValueError:
        raise error(f"{option} {item}: {value!r} is not a number (expected NAME=NUMBER)") from None
    if not math.isfinite(number):
        # Worded as the run checks word a non-finite parameter given through the Python API.
        raise error(f"{option} {item}: parameter {name!r} = {value} is not finite")
    return number


def parse_times(values, option, error=LagrangeGenError):
    """``['0.5', '1', '2:3:0.5']`` (--t-eval) -> array([0.5, 1, 2, 2.5, 3]): numbers and ranges
    START:STOP:STEP, STOP included when a step lands on it (to 1e-9 of a step, so 0:0.3:0.1 ends
    at 0.3). A malformed item is ``error`` naming ``option`` and the item."""
    import numpy as np
    times = []
    for item in values or ():
        parts = item.split(":")
        try:
            numbers = [float(part) for part in parts]
        except ValueError:
            numbers = None
        if numbers is None or len(numbers) not in (1, 3) or not all(map(math.isfinite, numbers)):
            raise error(f"{option} {item}: expected a finite time or START:STOP:STEP, "
                        f"e.g. {option} 0:10:0.01")
        if len(numbers) == 1:
            times.append(numbers[0])
            continue
        start, stop, step = numbers
        if step <= 0 or stop < start:
            raise error(f"{option} {item}: a range START:STOP:STEP needs STEP > 0 and "
                        f"STOP >= START, e.g. {option} 0:10:0.01")
        if step > stop - start > 0:      # sweep's --grid reads START:STOP:COUNT
            raise error(f"{option} {item}: STEP {parts[2]} is longer than the range; the third "
                        f"number is a step (e.g. {option} {parts[0]}:{parts[1]}:"
                        f"{(stop - start) / 100:g} for 101 times), not a count as in --grid")
        count = math.floor((stop - start) / step + 1e-9) + 1
        times.extend(start + step * np.arange(count))
    return np.array(times, dtype=float)


def method_name(name, error=LagrangeGenError):
    """``name`` (--method) when it is a method; else ``error``, one line with the closest names
    (steppers/core/registry.py unknown_method)."""
    from ..steppers.core.registry import METHODS, unknown_method
    if name not in METHODS:
        raise error(f"--method: {unknown_method(name)}")
    return name


def out_dir(model_path, given):
    """The folder for the modules of ``model_path``: ``given`` (-o / --gen-dir), else the model
    file's default (codegen.keys.default_generated_dir), which does not depend on the working
    directory."""
    from ..codegen.keys import default_generated_dir
    return default_generated_dir(model_path) if given is None else given


def velocity_names(values):
    """``['th_dot,x_dot']`` or ``['th_dot', 'x_dot']`` (--keep) -> ('th_dot', 'x_dot')."""
    return tuple(name.strip() for text in values or () for name in text.split(",") if name.strip())


@contextlib.contextmanager
def one_line_warnings(stream=None):
    """Warnings raised inside the block are printed as they come, as one
    ``lagrange-gen: warning: MESSAGE`` line each on stderr (no source line; a repeated message
    once)."""
    seen = set()

    def show(message, category, filename, lineno, file=None, line=None):
        text = str(message).strip().replace("\n", " ")
        if text not in seen:
            seen.add(text)
            print(f"lagrange-gen: warning: {text}", file=stream or sys.stderr, flush=True)

    with warnings.catch_warnings():
        warnings.simplefilter("always")
        warnings.showwarning = show
        yield
