"""lagrange-gen: write the physics once as energies in SymPy, get fast trustworthy simulation code.

Public API (explicit re-exports)::

    from lagrange_gen import Model, coordinates, parameters, t, PointForce, Event, Drawing, load_model
    from lagrange_gen import kinetic_energy, gravity_potential (sympy.physics.mechanics bodies), equations
    from lagrange_gen import load, import_generated, simulate
    from lagrange_gen import ensemble, grid, EnsembleResult

The modelling names load sympy on first use only, so that importing a generated module (which
imports lagrange_gen for its runtime helpers) stays fast.
"""

from importlib import import_module

from .errors import (BlowUp, EnergyWarning, GenerationError, LagrangeGenError, ModelError,
                     NewtonDivergence, SimulationError, SingularMass, SingularNewtonMatrix,
                     StaleModuleError)

_LAZY = {
    "Model": "model", "PointForce": "model", "coordinates": "model", "parameters": "model",
    "t": "model", "load_model": "model_file", "SaintVenant": "model", "DryFriction": "model",
    "Event": "model", "Drawing": "model", "kinetic_energy": "bodies", "gravity_potential": "bodies", "equations": "equations", "inputs": "model",
    "Signal": "control", "linearize": "linearization", "equilibrium": "linearization",
    "Stepper": "stepper_api", "step_jacobian": "step_derivatives",
    "import_generated": "loader", "load": "loader",
    "simulate": "simulation", "Trajectory": "trajectory",
    "ensemble": "ensemble_run", "grid": "ensemble_inputs", "EnsembleResult": "ensemble_run",
}

__all__ = sorted(_LAZY) + [
    "LagrangeGenError", "ModelError", "GenerationError", "StaleModuleError", "SimulationError",
    "NewtonDivergence", "SingularNewtonMatrix", "SingularMass", "BlowUp", "EnergyWarning",
]


def __getattr__(name):
    if name in _LAZY:
        value = getattr(import_module(f".{_LAZY[name]}", __name__), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'lagrange_gen' has no attribute {name!r}")
