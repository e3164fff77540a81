"""lagrange-gen: write the physics once as energies in SymPy, get fast trustworthy simulation code.

Public API (explicit re-exports)::

    from lagrange_gen import Model, coordinates, parameters, t, PointForce, load_model
"""

from .errors import (BlowUp, GenerationError, LagrangeGenError, ModelError, NewtonDivergence,
                     SimulationError, SingularMass, StaleModuleError)
from .model import Model, PointForce, coordinates, load_model, parameters, t

__all__ = [
    "Model", "PointForce", "coordinates", "parameters", "t", "load_model",
    "LagrangeGenError", "ModelError", "GenerationError", "StaleModuleError", "SimulationError",
    "NewtonDivergence", "SingularMass", "BlowUp",
]

from .loader import import_generated, load  # noqa: E402

__all__ += ["import_generated", "load"]
