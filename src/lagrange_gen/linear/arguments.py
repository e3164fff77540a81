"""The arguments of a linearization: the parameter vector with the inputs' slots, state
vectors checked against the model's size, and the kernels a module must have."""

from __future__ import annotations

import numpy as np

from ..errors import SimulationError
from ..run.control import parameter_vector  # noqa: F401 (the linearizations' p; run/ owns it)

__all__ = ["parameter_vector", "as_vector", "need_kernels"]


def need_kernels(module, *names):
    """SimulationError (one line) when the generated module lacks one of the kernels ``names``."""
    missing = [n for n in names if not hasattr(module, n)]
    if missing:
        raise SimulationError(f"{module.NAME}: module {module.__file__} has no kernel "
                              f"{', '.join(missing)} (linearize needs it); regenerate it for all "
                              "methods: lagrange-gen <model file>")


def as_vector(x, n, what, module):
    """x (n,) as a contiguous float array (zeros for None); SimulationError for another size."""
    x = np.ascontiguousarray(np.zeros(n) if x is None else x, dtype=np.float64).ravel()
    if x.shape != (n,):
        raise SimulationError(f"{module.NAME}: {what} has {x.size} entries for {n} coordinates")
    return x
