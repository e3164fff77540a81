"""A step API for control loops written in Python: one call advances one (or k) steps.

    stepper = lg.Stepper("models/cart_pole.py", "midpoint", h=1e-3, q0=[0, 0.1])
    for _ in range(1000):
        u = -K @ stepper.state           # any Python controller
        stepper.step(u)                  # one step with u held over it (zero-order hold)
    stepper.t, stepper.q, stepper.v

The method's workspace, the momentum and the saved fields are allocated once, in the
constructor, inside a numba jitclass that holds them; ``step`` writes u into the inputs' slots
of p (the last N_INPUTS entries) and calls the method's jitted ``step`` k times, so a call costs
one dispatch into compiled code (measured by ``lagrange-gen bench stepapi``). The jitclass is
compiled in this process for each (module, method) and kept; numba does not cache it on disk.
Failures raise the exception simulate raises for that status (failures.raise_for_status).
"""

from __future__ import annotations

import importlib
import math

import numpy as np
from .checks import vector
from .control import input_slots, parameter_vector
from ..errors import SimulationError
from ..jit import njit
from ..jit.api import jitclass, typeof
from ..jit.compile_notice import first_use_notice
from .failures import raise_for_status
from .params import is_number
from ..steppers.core import status as st
from ..steppers.core import registry
from ..steppers.core.options import fast_loop
from ..steppers.core.state_checks import check_state
from ..steppers.core.method_spec import make_settings

__all__ = ["Stepper"]

_CORES = {}


def _core_class(module, method, settings_type, ws_type):
    """The jitclass holding one stepper's state and buffers (kept per module and method)."""
    key = (module.__name__, module.KEY, method, settings_type, ws_type)
    if key in _CORES:
        return _CORES[key]
    stepper, kern = importlib.import_module(f"lagrange_gen.steppers.methods.{method}"), module
    spec = [("q", typeof(np.zeros(1))), ("v", typeof(np.zeros(1))), ("mom", typeof(np.zeros(1))),
            ("p", typeof(np.zeros(1))), ("extra", typeof(np.zeros(1))), ("clock", typeof(np.zeros(1))),
            ("info", typeof(np.zeros(1))), ("settings", settings_type), ("ws", ws_type),
            ("h", typeof(1.0)), ("first", typeof(1))]

    @fast_loop
    def _advance(q, v, mom, p, settings, ws, extra, clock, info, h, k):
        """k steps; clock = [t0, steps done, t]; info = [iterations, residual]. A function
        of its own without reference counting: jitclass methods count references on every
        attribute read, which cost as much as the step itself (steppers/core/options.py)."""
        for _ in range(k):
            t = clock[0] + clock[1] * h
            status, iters, resid = stepper.step(kern, q, v, mom, t, h, p, settings, ws, extra)
            info[0] = iters
            info[1] = resid
            if status != 0:
                return status
            clock[1] += 1.0
            clock[2] = clock[0] + clock[1] * h
            status = check_state(q, v, settings.blowup_bound)
            if status != 0:
                return status
        return 0

    class Core:
        def __init__(self, q, v, mom, p, extra, clock, info, settings, ws, h, first):
            self.q, self.v, self.mom, self.p, self.extra = q, v, mom, p, extra
            self.clock, self.info, self.settings, self.ws = clock, info, settings, ws
            self.h, self.first = h, first

        def prepare(self):
            return stepper.prepare(kern, self.q, self.v, self.mom, self.clock[2], self.p,
                                   self.settings, self.ws, self.extra)

        def advance(self, k):
            return _advance(self.q, self.v, self.mom, self.p, self.settings, self.ws,
                            self.extra, self.clock, self.info, self.h, k)

        def step_scalar(self, u, k):
            if self.p[self.first] != u:     # a changed input invalidates prepare's cache
                self.p[self.first] = u
                status = self.prepare()
                if status != 0:
                    return status
            return self.advance(k)

        def step_vector(self, u, k):
            changed = False
            for j in range(u.shape[0]):
                changed |= self.p[self.first + j] != u[j]
                self.p[self.first + j] = u[j]
            if changed:
                status = self.prepare()
                if status != 0:
                    return status
            return self.advance(k)

    _CORES[key] = jitclass(spec)(Core)
    return _CORES[key]


_MAKERS = {}


def _workspace(module, method):
    """The method's workspace namedtuple for this module (its jitted maker kept per module)."""
    key = (module.__name__, module.KEY, method)
    if key not in _MAKERS:
        stepper, kern, n = (importlib.import_module(f"lagrange_gen.steppers.methods.{method}"), module,
                            module.N_COORDS)

        @njit
        def make():
            return stepper.workspace(kern, n)
        _MAKERS[key] = make
    return _MAKERS[key]()


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
        self.module, self.method, self.h, self.n_inputs = module, method, float(h), k
        self.settings = make_settings(spec, settings)
        p = parameter_vector(module, params)
        # The compiled step indexes q and v up to n - 1 without bounds checks.
        self.q = vector("q0", q0, n, module.COORDS).copy()
        self.v = vector("v0", v0, n, module.COORDS).copy()
        self.p = p
        self._clock, self._info = np.array([float(t0), 0.0, float(t0)]), np.zeros(2)
        self._failure = None        # the message of the failure that ended this stepper
        self._label = f"Stepper({method}) for {module.NAME}"
        self._warm = set()          # the core's methods step() has called (compiled) already
        with first_use_notice(self._label):
            ws = _workspace(module, method)
            cls = _core_class(module, method, typeof(self.settings), typeof(ws))
            self._core = cls(self.q, self.v, np.zeros(n), p, np.zeros(0), self._clock,
                             self._info, self.settings, ws, self.h, first)
            status = self._core.prepare()
        self._check(status, 0)

    @property
    def t(self):
        return self._clock[2]

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
        core = self._core
        if u is None:
            kind = "advance"
        elif self.n_inputs == 1 and isinstance(u, float):
            kind = "step_scalar"
        else:
            kind = "step_vector"
            u = np.asarray(u, dtype=np.float64).ravel()
            if u.shape[0] != self.n_inputs:
                raise SimulationError(f"Stepper: u has {u.shape[0]} entries for "
                                      f"{self.n_inputs} input(s)")
        if kind not in self._warm:          # numba compiles each method on its first call
            with first_use_notice(self._label):
                code = self._call(kind, u, k)
            self._warm.add(kind)
        elif u is None:
            code = core.advance(k)
        elif kind == "step_scalar":
            code = core.step_scalar(u, k)
        else:
            code = core.step_vector(u, k)
        if code:
            try:
                self._check(code, k)
            except SimulationError as exc:
                self._failure = str(exc)
                raise

    def _call(self, kind, u, k):
        """The core's method ``kind`` for step(u, k)."""
        return self._core.advance(k) if kind == "advance" else getattr(self._core, kind)(u, k)

    def _check(self, code, k):
        if code == st.OK:
            return
        n = self.module.N_COORDS
        last = np.concatenate(([self.t], self.q, self.v, self._info))
        raise_for_status(code, self.module, self.method, self.steps + 1, self.steps + k, last,
                         getattr(self.settings, "max_iter", 0), self.h, self.p)
        raise SimulationError(f"Stepper: status {code} at t = {self.t:g} (n = {n})")
