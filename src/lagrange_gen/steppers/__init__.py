"""The shared stepper library: one integrator per module, generic over the generated kernels.

methods/: one module per method. Unconstrained: explicit_euler, symplectic_euler, verlet,
midpoint, implicit_euler, rk4, dop853, composition, composition6. Constrained (holonomic
Phi(q) = 0): rattle, constrained_midpoint, constrained_implicit_euler, spook (regularized),
index1 (the acceleration-level bad example). Nonsmooth elements: nonsmooth_euler.
core/: what they share: base.py states the rules every method follows and holds the run loop;
registry.py lists the methods (registry.METHODS, registry.INFO), codegen.glue writes the cached
``run_<method>`` glue into generated modules; lagrange_gen.simulate is the Python driver.
The steppers import jit and numpy, never sympy, derive or codegen.
"""
