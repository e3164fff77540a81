"""What every stepper method is built on: the run loop and its rules (base), the adaptive loop
(adaptive), Newton (newton), events and Hermite interpolation (events, hermite), the work
integral (work), linear algebra (linalg), status codes (status), the shared pieces of the
constrained, partitioned and explicit Runge-Kutta methods, a method's declaration
(method_spec) and the registry of methods (registry). Imports numba (through jit) and numpy;
never sympy, derive or codegen."""
