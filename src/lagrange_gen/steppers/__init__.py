"""The shared stepper library: one integrator per module, generic over the generated kernels.

methods/: one module per method; its __init__ states the rules every method follows.
Unconstrained: explicit_euler, symplectic_euler, verlet, midpoint, implicit_euler, rk4, dop853,
composition, composition6. Constrained (holonomic Phi(q) = 0): rattle, constrained_midpoint,
constrained_implicit_euler, spook (regularized), index1 (the acceleration-level bad example).
Nonsmooth elements: nonsmooth_euler.
core/: what they share: run_loop.py holds the run loop, layout.py the layout of its buffers;
registry.py lists the methods (registry.METHODS, registry.INFO); jit/specialized.py writes a
generated module's cached ``run_<method>`` glue (codegen.glue's text); lagrange_gen.simulate is
the Python driver.
The steppers import jit and numpy, never sympy, derive or codegen.
"""
