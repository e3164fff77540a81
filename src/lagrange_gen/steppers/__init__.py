"""The shared stepper library: one integrator per module, generic over the generated kernels.

Unconstrained: explicit_euler, symplectic_euler, verlet, midpoint, implicit_euler, rk4,
composition. Constrained (holonomic Phi(q) = 0): rattle, constrained_midpoint,
constrained_implicit_euler, spook (regularized), index1 (the acceleration-level bad example).
Nonsmooth elements: nonsmooth_euler. See registry.METHODS and registry.INFO; base.py states the rules every method follows and holds the
run loop; registry.py emits the cached ``run_<method>`` glue into generated modules;
lagrange_gen.simulate is the Python driver.
"""

from ..numba_inline_copy import install as _install_inline_copy

# numba's inliner copies a callee's scope once per block; the steppers inline large functions
# (lagrange_gen/numba_inline_copy.py measures it).
_install_inline_copy()
