"""One integrator per module, each ending with its ``SPEC`` (core.method_spec); the list of
methods is core.registry.METHODS. A method imports steppers.core, jit and nonsmooth only.

The rules every method module (``steppers/methods/<method>.py``) follows:

* One integrator per module, with a module docstring stating the scheme, its order and the
  properties the tests check.
* A declaration ``SPEC = method_spec.Spec(...)`` at the end of the module (core/method_spec.py):
  name, order, family, the models it applies to, its typed settings record, the kernels it
  calls and the named fields it saves per output row.
* Three jitted functions with the same signatures in every fixed-step module::

      workspace(kern, n) -> a namedtuple of the method's named scratch arrays
      prepare(kern, q, v, mom, t, p, settings, ws, extra) -> status
      step(kern, q, v, mom, t, h, p, settings, ws, extra)
          -> (status, newton_iterations, newton_residual)

  ``workspace`` allocates once per run (run_loop calls it); ``settings`` is the method's
  settings record (a NamedTuple, fields read by name); ``extra`` (n_saved,) holds the fields the
  method saves per output row (SPEC.saved, in that order), carried from step to step and from
  one chunk of a run to the next. ``prepare`` fills whatever per-run state the method carries
  between steps (the momentum ``mom = H(q) v``, a cached acceleration in its workspace);
  ``step`` advances (q, v, mom) from t to t + h in place. On failure ``step`` leaves q, v and
  mom at the start of the step, so the driver reports the state it could not step from.
* No ``run`` function: the generated glue ``run_<method>`` calls ``run_loop``
  (core/run_loop.py) with the method's module and the stepping loop it binds for it
  (``stepping_loop``; lagrange_gen.codegen.glue says why the glue exists); adaptive methods
  have their own loop (core/adaptive.py) and their own set of functions (see there). ``step``
  is declared ``@njit(inline=inline_step, **FAST)`` (core/options.py).
* No allocation per step: the workspace is allocated once per run and passed to ``step``.
* Failures are status codes (lagrange_gen.steppers.core.status), never garbage and never
  exceptions.

Loops over the coordinates run to ``kern.N_COORDS`` (core/options.py, "Loop bounds"). Shapes:
n coordinates; q, v, mom (n,); p (n_params,); extra (n_saved,).
"""
