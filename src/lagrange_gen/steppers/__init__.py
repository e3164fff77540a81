"""The shared stepper library: one integrator per module, generic over the generated kernels.

explicit_euler, symplectic_euler, verlet, midpoint, implicit_euler, rk4, composition (see
registry.METHODS and registry.INFO); base.py states the rules every method follows and holds the
run loop; registry.py emits the cached ``run_<method>`` glue into generated modules;
lagrange_gen.simulate is the Python driver.
"""
