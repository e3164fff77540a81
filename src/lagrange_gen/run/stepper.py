"""A step API for control loops written in Python: one call advances one (or k) steps.

    stepper = lg.Stepper("models/cart_pole.py", "midpoint", h=1e-3, q0=[0, 0.1])
    for _ in range(1000):
        u = -K @ stepper.state           # any Python controller
        stepper.step(u)                  # one step with u held over it (zero-order hold)
    stepper.t, stepper.q, stepper.v

The method's workspace, the momentum and the saved fields are allocated once, in the
constructor, in a StepperState (steppers/core/step_api.py) that also holds the model's kernel
table; ``step`` calls the method's portable ``stepper_step_<method>`` (codegen/glue.py), which
writes u into the inputs' slots of p (the last N_INPUTS entries) and runs the method's step k
times: one dispatch into compiled code per call (measured by ``lagrange-gen bench stepapi``).
Those functions are compiled once per method for every model and kept in numba's cache, so a
Stepper in a new process, or on a new model, compiles nothing once the method has been used.
Failures raise the exception simulate raises for that status (failures.raise_for_status).
"""

from __future__ import annotations

import math

import numpy as np
from .checks import vector
from .control import input_slots, parameter_vector
from ..errors import SimulationError
from ..jit.compile_notice import first_use_notice
from .failures import raise_for_status
from .params import is_number
from ..steppers.core import status as st
from ..steppers.core import registry
from ..steppers.core.method_spec import make_settings

__all__ = ["Stepper"]

#: u of a step that keeps the inputs as they are.
_NO_INPUTS = np.zeros(0)


class Stepper:
    """stepper = Stepper(module, method, h, params=None, q0=None, v0=None, t0=0.0, **settings).

    ``module``: a generated module or a model file; ``method``: a fixed-step method for an
    unconstrained model without nonsmooth elements; ``settings`` as simulate's. ``step(u, k=1)``
    holds u (float or (n_inputs,); None keeps the previous value) over k steps. ``q``, ``v``
    (n,) are live views of the state, ``state`` = (q, v) (2n,) a copy, ``t`` the time."""

    def __init__(self, module, method="midpoint", h=None, params=None, q0=None, v0=None, t0=0.0,
                 **settings):
        from .simulate import load_module
        if method not in registry.METHODS:
            raise SimulationError(f"Stepper: {registry.unknown_method(method)}")
        module = load_module(module, method=method)
        spec = registry.spec(method)
        if (spec.adaptive or spec.constraints or spec.contacts or spec.nonholonomic
                or getattr(module, "N_ELEMENTS", 0) or module.N_CONSTRAINTS
                or getattr(module, "N_CONTACTS", 0) or getattr(module, "N_NONHOLONOMIC", 0)):
            raise SimulationError(f"Stepper: {method} on {module.NAME}: the step API takes a "
                                  "fixed-step method on a model without constraints, elements "
                                  "or contacts")
        if not (is_number(h) and math.isfinite(h) and h > 0):
            raise SimulationError(f"Stepper: give a finite step h > 0, got {h!r}")
        if not (is_number(t0) and math.isfinite(t0)):
            raise SimulationError(f"Stepper: t0 must be a finite number, got {t0!r}")
        n, (first, k) = module.N_COORDS, input_slots(module)
        self.module, self.method, self.n_inputs = module, method, k
        self.settings = make_settings(spec, settings)
        p = parameter_vector(module, params)
        # The compiled step indexes q and v up to n - 1 without bounds checks.
        self.q = vector("q0", q0, n, module.COORDS).copy()
        self.v = vector("v0", v0, n, module.COORDS).copy()
        self.p = p
        # [t0, steps done, t, h]: the state's clock, read by the compiled steps
        self._clock, self._info = np.array([float(t0), 0.0, float(t0), float(h)]), np.zeros(2)
        self._failure = None        # the message of the failure that ended this stepper
        self._label = f"Stepper({method}) for {module.NAME}"
        self._warm = False          # step() has run (its function loaded or compiled)
        from ..jit.portable import glue_function, kernel_table
        self._step = glue_function(method, f"stepper_step_{method}")
        self._u = np.zeros(k)        # u of step(), written here (no array made per call)
        with first_use_notice(self._label):
            table = kernel_table(module, method)
            #: the method's workspace (its arrays are the compiled state's)
            self.ws = glue_function(method, f"stepper_workspace_{method}")(table, n)
            self._state = glue_function(method, f"stepper_new_{method}")(
                table, self.q, self.v, p, self._clock, self._info, self.settings, self.ws, first)
            status = glue_function(method, f"stepper_prepare_{method}")(self._state)
        self._check(status, 0)

    @property
    def t(self):
        return self._clock[2]

    @property
    def h(self):
        """The step; it may be changed between calls (a negative one steps back in time)."""
        return self._clock[3]

    @h.setter
    def h(self, value):
        if not (is_number(value) and math.isfinite(value) and value != 0):
            raise SimulationError(f"Stepper: the step h must be a finite nonzero number, got {value!r}")
        self._clock[3] = float(value)

    @property
    def steps(self):
        return int(self._clock[1])

    @property
    def state(self):
        return np.concatenate((self.q, self.v))

    def step(self, u=None, k=1):
        """Advance k steps with the inputs held at u; returns nothing, raises on failure (and
        on any later call: the state is the failed one)."""
        if not (is_number(k) and int(k) == k and k >= 1):
            raise SimulationError(f"Stepper.step: k must be a positive integer (the number of "
                                  f"steps), got {k!r}")
        if self._failure is not None:
            raise SimulationError(f"Stepper: this run failed at t = {self.t:g} ({self._failure}); "
                                  f"make a new Stepper to start again")
        k = int(k)
        if u is None:
            inputs = _NO_INPUTS
        elif self.n_inputs == 1 and isinstance(u, float):
            inputs = self._u
            inputs[0] = u
        else:
            inputs = np.asarray(u, dtype=np.float64).ravel()
            if inputs.shape[0] != self.n_inputs:
                raise SimulationError(f"Stepper: u has {inputs.shape[0]} entries for "
                                      f"{self.n_inputs} input(s)")
        if self._warm:
            code = self._step(self._state, inputs, k)
        else:                                  # loaded or compiled on the first call
            with first_use_notice(self._label):
                code = self._step(self._state, inputs, k)
            self._warm = True
        if code:
            try:
                self._check(code, k)
            except SimulationError as exc:
                self._failure = str(exc)
                raise

    def _check(self, code, k):
        if code == st.OK:
            return
        n = self.module.N_COORDS
        last = np.concatenate(([self.t], self.q, self.v, self._info))
        raise_for_status(code, self.module, self.method, self.steps + 1, self.steps + k, last,
                         getattr(self.settings, "max_iter", 0), self.h, self.p)
        raise SimulationError(f"Stepper: status {code} at t = {self.t:g} (n = {n})")
