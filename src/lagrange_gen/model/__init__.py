"""The model front end: what a user writes, as SymPy, before anything is derived.

Model (model), coordinates, parameters and time (symbols), point forces and nonsmooth elements
(loads), events and the checks on user expressions (expressions), sympy.physics.mechanics
input (mechanics), drawings for animations (drawing), and running a model file
(model_file). Imports sympy and errors only; nothing here imports derive, codegen or the
runtime. The names of ``lagrange_gen.model`` (Model, coordinates, ...) load on first use.
"""

from importlib import import_module

__all__ = ["Coordinate", "Velocity", "Parameter", "PointForce", "SaintVenant", "DryFriction",
           "Event", "Model", "Drawing", "coordinates", "parameters", "t", "inputs"]


def __getattr__(name):
    if name in __all__:
        return getattr(import_module(".model", __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
