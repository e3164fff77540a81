"""Running a generated module: simulate and what surrounds it.

simulate (simulate) with its chunked drivers (fixed_driver, adaptive_driver), the inputs checked
before a run (checks), status -> error (failures), the energy check, consistent initial states
(consistent), parameters (params), importing generated modules (loader), Trajectory and its
I/O (trajectory, trajectory_io), control inputs (control), the one-step Stepper (stepper) and
ensembles (ensemble, ensemble_inputs, ensemble_dask). May import steppers, jit, codegen.keys,
errors; never sympy on a cold simulate of a generated module.
"""
