"""Verification as library functions, separate from the timing suites of ``lagrange_gen.bench``:

* ``runs``: generated modules of model files, parameter vectors, one guarded ``simulate`` run;
* ``stability``: step matrices measured from the real steppers, spectral radius, phase per step
  and the closed forms of rho(tau) of every method (HARD_CASES case 3);
* ``reference``: right-hand sides for scipy, checked DOP853 references, the same equations
  derived independently by sympy.physics.mechanics, closed-form solutions;
* ``scenes``: the hard cases as scenes (model, start, end time, what "stable" means);
* ``hard_cases`` and ``hard_constrained``: HARD_CASES 3-8 with their PASS/FAIL verdicts;
* ``harness``: the verdict of a run of the differential harness from pytest's output.

The bench imports these to time and render; the tests import them to assert.
"""
