"""One integrator per module, each ending with its ``SPEC`` (core.method_spec); the list of
methods is core.registry.METHODS. A method imports steppers.core, jit and nonsmooth only."""
