"""What every stepper method is built on: the fixed-step run loop (run_loop), the layouts of the
buffers it shares with its driver (layout) and their writers (output), the adaptive loop
(adaptive), numba options and loop bounds (options), the state check after each step
(state_checks), Newton and its stopping rules (newton), events and Hermite interpolation
(events, hermite), the work integral (work), the Legendre transform (legendre), vector helpers
and solves (solve), linear algebra (linalg), status codes (status), the shared pieces of the
constrained, partitioned and explicit Runge-Kutta methods, a method's declaration
(method_spec) and the registry of methods (registry). Imports numba (through jit) and numpy;
never sympy, derive or codegen."""
