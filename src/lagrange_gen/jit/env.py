"""The package's boolean environment variables, read in one place (``env_flag``):
$LAGRANGE_GEN_BACKGROUND_COMPILE and $LAGRANGE_GEN_INTERPRETED (jit/first_run.py),
$LAGRANGE_GEN_NATIVE (jit/native.py). It imports nothing of the package, so that every module
may read a variable without an import circle."""

from __future__ import annotations

import os
import warnings

#: The words of a boolean environment variable (env_flag), in any case.
FLAG_WORDS = {"1": True, "on": True, "yes": True, "true": True,
              "0": False, "off": False, "no": False, "false": False}

#: (variable, value) pairs already warned about in this process (env_flag).
_WARNED: set = set()


def env_flag(name, default: bool) -> bool:
    """The boolean environment variable ``name``: one of FLAG_WORDS (any case, spaces around
    ignored); unset or empty: ``default``; anything else: ``default`` after one warning line
    (once per process and value) naming the variable and the value. Every boolean variable of
    the package is read here."""
    raw = os.environ.get(name, "")
    text = raw.strip().lower()
    if not text:
        return default
    if text in FLAG_WORDS:
        return FLAG_WORDS[text]
    if (name, raw) not in _WARNED:
        _WARNED.add((name, raw))
        warnings.warn(f"lagrange-gen: ${name}={raw!r} is not one of 1/0, on/off, yes/no, "
                      f"true/false; taken as {'on' if default else 'off'} (the default)",
                      RuntimeWarning, stacklevel=3)
    return default
