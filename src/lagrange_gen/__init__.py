"""lagrange-gen: write the physics once as energies in SymPy, get fast trustworthy simulation code.

Public API (explicit re-exports)::

    from lagrange_gen import Model, coordinates, parameters, t, PointForce, Event, Drawing, load_model
    from lagrange_gen import kinetic_energy, gravity_potential (sympy.physics.mechanics bodies), equations
    from lagrange_gen import load, import_generated, simulate
    from lagrange_gen import ensemble, grid, EnsembleResult

The modelling names load sympy on first use only, so that importing a generated module (which
imports lagrange_gen for its runtime helpers) stays fast; ``dir(lagrange_gen)`` lists them all
the same. ``lagrange_gen.__version__`` is the installed distribution's version.
"""

from importlib import import_module as _import_module

from .errors import (BlowUp, EnergyWarning, GenerationError, LagrangeGenError, ModelError,
                     NewtonDivergence, SimulationError, SingularMass, SingularNewtonMatrix,
                     StaleModuleError)

_LAZY = {
    "Model": "model.model", "PointForce": "model.model", "coordinates": "model.model",
    "parameters": "model.model", "t": "model.model", "SaintVenant": "model.model",
    "DryFriction": "model.model", "Contact": "model.model", "Event": "model.model", "Drawing": "model.model",
    "inputs": "model.model", "load_model": "model.model_file", "kinetic_energy": "model.bodies", "gravity_potential": "model.bodies",
    "from_urdf": "model.urdf",
    "equations": "derive.equations", "Equations": "derive.equations",
    "Signal": "run.control", "linearize": "linear.linearize", "equilibrium": "linear.linearize",
    "linearize_nonholonomic": "linear.nonholonomic", "rolling_contact": "model.rolling",
    "RollingContact": "model.rolling",
    "Stepper": "run.stepper", "step_jacobian": "linear.step_derivatives",
    "import_generated": "run.loader", "load": "run.loader",
    "simulate": "run.simulate", "Trajectory": "run.trajectory",
    "ensemble": "run.ensemble", "grid": "run.ensemble_inputs", "EnsembleResult": "run.ensemble",
    "fit": "identify.fit", "Fit": "identify.fit",
}

__all__ = sorted(_LAZY) + [
    "LagrangeGenError", "ModelError", "GenerationError", "StaleModuleError", "SimulationError",
    "NewtonDivergence", "SingularNewtonMatrix", "SingularMass", "BlowUp", "EnergyWarning",
]


#: __version__ when the package runs from a source tree that was never installed (no metadata).
_UNKNOWN_VERSION = "0+unknown"


def _installed_version():
    """The version pip recorded for the lagrange-gen distribution, else _UNKNOWN_VERSION;
    read on first use of __version__ (importlib.metadata costs an import at startup)."""
    from importlib.metadata import PackageNotFoundError, version
    try:
        return version("lagrange-gen")
    except PackageNotFoundError:
        return _UNKNOWN_VERSION


def __getattr__(name):
    if name in _LAZY:
        value = getattr(_import_module(f".{_LAZY[name]}", __name__), name)
        globals()[name] = value
        return value
    if name == "__version__":
        globals()[name] = value = _installed_version()
        return value
    raise AttributeError(f"module 'lagrange_gen' has no attribute {name!r}")


def __dir__():
    """The module's attributes and every lazy public name (tab completion, ``dir()``)."""
    return sorted(set(globals()) | set(_LAZY) | {"__version__"})
