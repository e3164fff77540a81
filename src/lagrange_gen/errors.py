"""Exception hierarchy.

User errors carry a one-line message that names the file, symbol, step or value; the CLI prints
that line and exits non-zero without a traceback (``--debug`` shows it).
"""


class LagrangeGenError(Exception):
    """Base class of every error lagrange-gen raises on purpose."""


class ModelError(LagrangeGenError):
    """The model file or the Model it defines is invalid."""


class GenerationError(LagrangeGenError):
    """Derivation or code generation failed, or a generated file is missing or stale."""


class StaleModuleError(GenerationError):
    """A generated module does not match its model or the installed generator."""


class SimulationError(LagrangeGenError):
    """A simulation could not proceed; subclasses name the numerical failure."""

    def __init__(self, message, step=None, time=None, state=None, residual=None):
        super().__init__(message)
        self.step = step
        self.time = time
        self.state = state
        self.residual = residual


class NewtonDivergence(SimulationError):
    """Newton's method did not converge within its iteration cap."""


class SingularMass(SimulationError):
    """The generalized inertia H(q) (in a constrained method: or J H^-1 J^T) is singular."""


class BlowUp(SimulationError):
    """The state (or its energy, or a Newton matrix) became non-finite, or the state grew past
    the blow-up bound."""


class SingularNewtonMatrix(NewtonDivergence):
    """The Newton matrix of an implicit step (its Jacobian, or the constrained KKT matrix) is
    singular although H(q) may be regular: Newton cannot proceed (reduce h)."""


class EnergyWarning(UserWarning):
    """A run on a conservative model lost (or gained) energy far beyond what its step allows
    (lagrange_gen.run.energy_check); the trajectory is kept, with the line in Trajectory.warnings."""


class IdentificationError(LagrangeGenError, ValueError):
    """The data do not determine the requested parameters (lagrange_gen.identify); the message
    says what is missing. A ValueError (bad input values) and a LagrangeGenError (the CLI prints
    its one-line message)."""
