"""Model inputs inside the stepping loop: a jitted controller or a sampled signal.

A model's inputs (``Model(inputs=[u1, ...])``) are the last N_INPUTS entries of its parameter
vector p, so every generated kernel reads them without a change of signature. Before each step
(and once at t0) the run loop (steppers/run_loop.run_loop, argument ``control``) calls a jitted
hook ``apply(c, t, q, v, p) -> changed`` that writes them: a zero-order hold over each step (a
changed input re-runs the method's prepare, which may have cached forces). Supplied by

* a controller ``u = f(t, q, qd, p)``, a numba-jitted function returning a float (one input),
  a 1-D array or a tuple (n_inputs), evaluated at the state at the start of each step; with
  ``control_params=c`` (a 1-D array of numbers: gains, set points) it is ``f(t, q, qd, p, c)``;
* a :class:`Signal` of samples (times (S,), values (S, n_inputs)), held between samples
  (``hold="zoh"``) or interpolated linearly (``hold="linear"``, evaluated at the middle of each
  step, which keeps an input error of O(h^2) in the step);
* constants: ``params={"u": 0.5}`` (an input is a parameter; no loop hook then).

Every hook has the one signature ``(c float64[::1], t float64, q, v, p float64[::1]) ->
bool`` and writes the trailing entries of p (as many as it has values): a controller's hook is a
small jitted wrapper (make_apply: the controller's value, of any of its three kinds, written into
p; c = control_params, empty without them), a Signal's is one library function
(_signal_apply, cached by numba) whose c is the samples as data (signal_data). So the loop
compiled for one hook runs them all: the portable controlled glue (jit/portable.py,
``run_<method>_controlled``), compiled once per method and cached on disk by numba, reaches the
hook through a function pointer. A controller's hooks (the wrapper, and the probe that checks its
value at the initial state) are written to a file named after the controller's content key
(run/controller_hooks.py, jit/function_key.py) and cached by numba there: a new process running
a controller it ran before compiles nothing, a new controller compiles only itself and its
hooks. The specialized loop of (module, method,
hook) (controlled_run: the hook inlined, faster per step, compiled in each process: numba does
not cache code that receives a jitted function) runs under jit="specialized", and under "auto"
when it is compiled in this process already or the portable controlled glue is not yet cached
(then a background process compiles that glue for the next process, jit/first_run.py).
Trajectories of a model with inputs carry ``saved["input_<name>"]`` (the input held over the
step that starts at each saved row) and, with outputs, ``saved["output_<name>"]`` (the
generated ``outputs`` kernel).
"""

from __future__ import annotations

import math

import numpy as np
from ..errors import SimulationError
from ..jit import njit
from ..jit.api import overload, types
from ..jit.python_calls import unchecked
from .params import resolve_params
from ..steppers.core.options import FAST

__all__ = ["Signal", "input_slots", "parameter_vector", "make_apply", "signal_data", "controlled_run",
           "resolve_inputs", "attach_inputs_outputs"]


class Signal:
    """Sampled inputs: times (S,) increasing, values (S,) or (S, n_inputs); hold "zoh" (the last
    sample before t) or "linear" (between samples; constant before the first and after the
    last sample)."""

    def __init__(self, times, values, hold="zoh"):
        if hold not in ("zoh", "linear"):
            raise SimulationError(f"Signal: hold={hold!r}; use 'zoh' or 'linear'")
        self.times = _samples("times", times)
        values = _samples("values", values)
        if self.times.ndim != 1:
            raise SimulationError(f"Signal: times must be a 1-d sequence, got shape {self.times.shape}")
        if values.ndim not in (1, 2):
            raise SimulationError(f"Signal: values must be (S,) or (S, n_inputs), got shape "
                                  f"{values.shape}")
        if len(self.times) == 0:
            raise SimulationError("Signal: no samples (give at least one time and value)")
        if len(values) != len(self.times):
            raise SimulationError(f"Signal: {len(self.times)} times for {len(values)} samples")
        for name, arr in (("times", self.times), ("values", values)):
            bad = np.argwhere(~np.isfinite(arr))
            if bad.size:
                raise SimulationError(f"Signal: {name} must be finite; {name}[{bad[0][0]}] = "
                                      f"{arr[tuple(bad[0])]!r}")
        steps = np.diff(self.times)
        if np.any(steps <= 0):
            k = int(np.argmax(steps <= 0)) + 1
            raise SimulationError(f"Signal: times must increase; times[{k}] = {self.times[k]:g} "
                                  f"after {self.times[k - 1]:g}")
        self.values = np.ascontiguousarray(values.reshape(len(values), -1))
        self.hold = hold

    def __call__(self, t):
        """The input (n_inputs,) the loop applies over a step evaluated at t (for checks)."""
        out = np.zeros(self.values.shape[1])
        none = np.zeros(0)
        _signal_apply(signal_data(self, 0.0), float(t), none, none, out)
        return out


def _samples(name, value):
    """``value`` as a C-contiguous float64 array, or a one-line SimulationError naming it."""
    try:
        return np.ascontiguousarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise SimulationError(f"Signal: {name} must be numbers, got {value!r}") from None


def _write_inputs(u, p):
    """The trailing entries of p = u (a float, a 1-D array or a tuple: as many entries as u
    has); True when an entry changed (jitted: see the overload)."""


@overload(_write_inputs, jit_options=FAST)
def _write_inputs_impl(u, p):
    if isinstance(u, (types.Float, types.Integer)):
        def impl(u, p):
            first = p.shape[0] - 1
            changed = p[first] != u
            p[first] = u
            return changed
    elif isinstance(u, types.Array):
        def impl(u, p):
            first = p.shape[0] - u.shape[0]
            changed = False
            for j in range(u.shape[0]):
                changed |= p[first + j] != u[j]
                p[first + j] = u[j]
            return changed
    elif isinstance(u, types.BaseTuple):
        def impl(u, p):
            first = p.shape[0] - len(u)
            changed = False
            j = 0
            for value in u:
                changed |= p[first + j] != value
                p[first + j] = value
                j += 1
            return changed
    else:
        raise TypeError(f"a controller returns a float, a 1-D array or a tuple, not {u}")
    return impl


def _value_into(u, out):
    """(ndim, size) of a controller's value u (a float: (0, 1)), its first entries (flattened)
    written into out: what the run checks before the loop writes u unchecked (jitted: see the
    overload)."""


@overload(_value_into, jit_options=FAST)
def _value_into_impl(u, out):
    if isinstance(u, (types.Float, types.Integer)):
        def impl(u, out):
            if out.shape[0]:
                out[0] = u
            return 0, 1
    elif isinstance(u, types.Array):
        def impl(u, out):
            j = 0
            for value in u.flat:
                if j < out.shape[0]:
                    out[j] = value
                j += 1
            return u.ndim, u.size
    elif isinstance(u, types.BaseTuple):
        def impl(u, out):
            j = 0
            for value in u:
                if j < out.shape[0]:
                    out[j] = value
                j += 1
            return 1, len(u)
    else:
        raise TypeError(f"a controller returns a float, a 1-D array or a tuple, not {u}")
    return impl


#: Entries of a Signal's data vector before its samples (signal_data).
_SIGNAL_HEAD = 4


def signal_data(signal, h):
    """The samples of ``signal`` as the data c (4 + S (1 + k),) of its hook _signal_apply:
    [linear (1.0 or 0.0), h / 2, S, k, times (S,), values (S, k) row by row]."""
    times, values = signal.times, signal.values
    head = [1.0 if signal.hold == "linear" else 0.0, 0.5 * h, len(times), values.shape[1]]
    return np.ascontiguousarray(np.concatenate((head, times, values.reshape(-1))))


@njit(cache=True, **FAST)
def _signal_apply(c, t, q, v, p):
    """The hook of a Signal, c = signal_data: the last k entries of p = the signal at t
    (zero-order hold) or at t + h/2 (linear); True when an entry changed."""
    linear, half = c[0] != 0.0, c[1]
    S, k = int(c[2]), int(c[3])
    times = c[_SIGNAL_HEAD:_SIGNAL_HEAD + S]
    at = _SIGNAL_HEAD + S                                 # values[i, j] = c[at + i * k + j]
    first = p.shape[0] - k
    s = t + half if linear else t
    i = np.searchsorted(times, s, side="right") - 1      # last sample at or before s
    changed = False
    w = 0.0
    if linear and 0 <= i < S - 1:
        w = (s - times[i]) / (times[i + 1] - times[i])
    i = min(max(i, 0), S - 1)
    for j in range(k):
        now = c[at + i * k + j]
        value = now if w == 0.0 else (1.0 - w) * now + w * c[at + (i + 1) * k + j]
        changed |= p[first + j] != value
        p[first + j] = value
    return changed


_HOOKS = {}


def make_apply(controller, with_params=False):
    """The hook apply(c, t, q, v, p) -> changed of a jitted controller u = f(t, q, qd, p)
    (c unused: an empty array), or with with_params u = f(t, q, qd, p, c): u written into the
    last entries of p (controller_hooks: cached on disk by the controller's content, so a new
    process running it compiles nothing). One per controller in a process; compiled with
    reference counting, which frees the array a controller may return at each step."""
    return _hooks(controller, with_params).apply


def _hooks(controller, with_params):
    """controller_hooks.ControllerHooks of a jitted controller, made once per process."""
    if not hasattr(controller, "py_func"):
        raise SimulationError(f"control: {getattr(controller, '__name__', controller)!r} is not "
                              "numba-jitted; decorate it with @numba.njit (it runs inside the loop)")
    _check_arity(controller, with_params)
    key = (controller, with_params)
    if key not in _HOOKS:
        from .controller_hooks import controller_hooks
        _HOOKS[key] = controller_hooks(controller, with_params)
    return _HOOKS[key]


def _check_arity(controller, with_params=False):
    """numba's "too many arguments" would come from inside the loop's compile: a controller must
    take (t, q, qd, p), or (t, q, qd, p, c) with control_params, checked on its Python
    function."""
    import inspect
    args = ("t, q, qd, p, c", (0.0, None, None, None, None)) if with_params else \
        ("t, q, qd, p", (0.0, None, None, None))
    try:
        inspect.signature(controller.py_func).bind(*args[1])
    except TypeError:
        given = " (control_params given)" if with_params else ""
        raise SimulationError(f"control: the controller {controller.__name__}"
                              f"{inspect.signature(controller.py_func)} must take "
                              f"({args[0]}){given}") from None
    except ValueError:         # no signature to read: numba tells
        pass


def control_params_vector(control, values):
    """control_params as a C-contiguous float64 vector (k,), or a SimulationError naming what is
    wrong: it needs a jitted controller, and finite numbers in a flat sequence."""
    if control is None or isinstance(control, Signal):
        what = "no controller" if control is None else "a Signal"
        raise SimulationError(f"control_params= are the parameters of a controller "
                              f"u = f(t, q, qd, p, c); control= is {what}")
    try:
        c = np.array(values, dtype=np.float64)
    except (TypeError, ValueError):
        raise SimulationError(f"control_params must be a sequence of numbers, got "
                              f"{values!r}") from None
    if c.ndim > 1:
        raise SimulationError(f"control_params must be a flat sequence of numbers, got an array "
                              f"of shape {c.shape}")
    c = np.ascontiguousarray(c.reshape(-1))
    bad = np.flatnonzero(~np.isfinite(c))
    if bad.size:
        raise SimulationError(f"control_params[{bad[0]}] = {float(c[bad[0]])!r} is not finite")
    return c


def blame_inputs(error, module, p, control, data=None):
    """``error`` (a SimulationError of a run with inputs from ``control``; data: its
    control_params c, None without) as one line that also names the inputs when the last values
    written to p (n_params,) are not finite: the failure (NaN state, singular matrix) then comes
    from them, not from the model; and, when the controller raises an exception at the
    failure's time and state (its hook then writes NaN, make_apply), that exception. Else
    ``error``."""
    first, k = input_slots(module)
    bad = [f"{name} = {value!r}" for name, value in zip(module.PARAMS[first:], p[first:].tolist())
           if not math.isfinite(value)]
    if not bad:
        return error
    if isinstance(control, Signal):
        source = "the Signal"
    else:
        source = f"the controller {control.__name__}"
        raised = _raised(control, error, module, p, data)
        if raised:
            source += f" (which raises {raised} at t = {error.time:g})"
    return type(error)(f"{error}; the input {', '.join(bad)} from {source} is not finite there",
                       step=error.step, time=error.time, state=error.state,
                       residual=error.residual)


def _raised(controller, error, module, p, data):
    """'ValueError: text' when ``controller`` called from Python at the time and state of
    ``error`` raises an exception, else None."""
    n = module.N_COORDS
    state = getattr(error, "state", None)
    if state is None or error.time is None or len(state) != 2 * n:
        return None
    q, v = np.ascontiguousarray(state[:n]), np.ascontiguousarray(state[n:])
    args = (float(error.time), q, v, p.copy())
    try:
        controller(*args) if data is None else controller(*args, data.copy())
    except Exception as exc:            # the user's exception, reported in the line
        return f"{type(exc).__name__}: {exc}".splitlines()[0]
    return None


def input_slots(module):
    """(first slot, n_inputs) of a module's inputs in p."""
    k = getattr(module, "N_INPUTS", 0)
    return len(module.PARAMS) - k, k


def parameter_vector(module, params=None, u=None):
    """p (n_params,) with the inputs' slots set to u (n_inputs,), default 0."""
    first, k = input_slots(module)
    defaults = list(module.DEFAULTS[:first]) + [0.0] * k
    p = resolve_params(module.PARAMS, defaults, params, model=module.NAME,
                       frozen=getattr(module, "FROZEN", None))
    if u is not None:
        u = np.atleast_1d(np.asarray(u, dtype=np.float64))
        if u.shape != (k,):
            raise SimulationError(f"{module.NAME}: u has {u.size} entries for {k} input(s) "
                                  f"({', '.join(module.PARAMS[first:]) or 'none'})")
        p[first:] = u
    return p


#: {(module name, KEY, method, hook): the controlled loop compiled in this process}.
_RUNS = {}


def controlled_run(module, method, apply):
    """run(q0, v0, t0, h, n_steps, save_every, p, settings, out_t, out_q, out_v, out_stats,
    out_extra, out_last, out_events, data): the fixed-step glue of ``method`` with the hook
    ``apply`` (compiled on first use in this process, then kept)."""
    import importlib
    from ..steppers.core import registry
    from ..steppers.core.run_loop import run_loop, stepping_loop
    key = (module.__name__, module.KEY, method, apply)
    if key not in _RUNS:
        stepper = importlib.import_module(f"lagrange_gen.steppers.methods.{method}")
        spec = registry.spec(method)
        n_saved = spec.n_saved(module.N_COORDS, module.N_CONSTRAINTS, module.N_ELEMENTS,
                               getattr(module, "N_CONTACTS", 0),
                               getattr(module, "N_NONHOLONOMIC", 0))
        kern, n_events = module, module.N_EVENTS
        if spec.adaptive:
            raise SimulationError(f"inputs from a controller or a signal need a fixed-step method; "
                                  f"{method} chooses its own steps")
        loop = stepping_loop(stepper, kern, n_events)

        @njit(error_model="numpy")
        def run(q0, v0, t0, h, n_steps, save_every, p, settings, out_t, out_q, out_v,
                out_stats, out_extra, out_last, out_events, data):
            return run_loop(stepper, loop, kern, n_saved, n_events, q0, v0, t0, h, n_steps,
                            save_every, p, settings, out_t, out_q, out_v, out_stats, out_extra,
                            out_last, out_events, apply, data)
        _RUNS[key] = run
    return _RUNS[key]


def resolve_inputs(module, params, control, h, t0=0.0, q0=None, v0=None, control_params=None):
    """(p (n_params,), hook, data) for a run: the parameters with the inputs' slots filled
    (controller and signal: by the loop's hook apply(data, t, q, v, p), data a float64 vector,
    see make_apply and signal_data; hook None for constant inputs). control_params: the
    controller's own parameters c (then u = f(t, q, qd, p, c)). A model input with no
    value (no control, no params entry, no default), or a controller whose value at (t0, q0,
    v0) has the wrong size, is a SimulationError naming it."""
    first, k = input_slots(module)
    names = list(module.PARAMS[first:])
    c = None if control_params is None else control_params_vector(control, control_params)
    if control is None:
        if params is None or isinstance(params, dict):
            missing = [u for u, d in zip(names, module.DEFAULTS[first:])
                       if d is None and u not in (params or {})]
            if missing:
                raise SimulationError(
                    f"{module.NAME}: input {missing[0]} has no value; give control= (a jitted "
                    f"controller u = f(t, q, qd, p) or a Signal) or params={{{missing[0]!r}: ...}} "
                    f"(--param {missing[0]}=... on the command line)")
        return resolve_params(module.PARAMS, module.DEFAULTS, params, model=module.NAME,
                              frozen=getattr(module, "FROZEN", None)), None, None
    if not k:
        raise SimulationError(f"{module.NAME}: control= given but the model has no inputs "
                              "(declare them with Model(inputs=[...]))")
    if isinstance(params, dict) and set(params) & set(names):
        raise SimulationError(f"{module.NAME}: input {sorted(set(params) & set(names))[0]} is "
                              "given both by control= and by params=")
    given = dict(params or {}) if isinstance(params, dict) or params is None else params
    defaults = list(module.DEFAULTS[:first]) + [0.0] * k
    p = resolve_params(module.PARAMS, defaults, given, model=module.NAME,
                       frozen=getattr(module, "FROZEN", None))
    if isinstance(control, Signal):
        if control.values.shape[1] != k:
            raise SimulationError(f"{module.NAME}: the Signal has {control.values.shape[1]} "
                                  f"value(s) per sample for {k} input(s) ({', '.join(names)})")
        return p, _signal_apply, signal_data(control, h)
    apply = make_apply(control, c is not None)
    if q0 is not None:
        _check_size(module, control, float(t0), q0, v0, p, names, c)
    return p, apply, np.zeros(0) if c is None else c


def _check_size(module, controller, t0, q0, v0, p, names, c=None):
    """The jitted loop writes a controller's value without bounds checks: its size must be
    n_inputs, checked here once, at the initial state, by the controller's probe hook (compiled
    with it, cached like it: controller_hooks)."""
    probe = _hooks(controller, c is not None).probe
    values = np.full(len(names), np.nan)
    ndim, size = probe(np.zeros(0) if c is None else c.copy(), t0,
                       np.ascontiguousarray(q0, dtype=np.float64),
                       np.ascontiguousarray(v0, dtype=np.float64), p.copy(), values)
    if ndim > 1 or size != len(names):
        raise SimulationError(f"{module.NAME}: the controller {controller.__name__} returns "
                              f"{size} value(s) at t0 for {len(names)} input(s) "
                              f"({', '.join(names)})")
    bad = [f"{name} = {value!r}" for name, value in zip(names, values.tolist()) if not math.isfinite(value)]
    if bad:
        raise SimulationError(f"{module.NAME}: the controller {controller.__name__} returns a "
                              f"non-finite input at t0 = {t0:g}: input {', '.join(bad)}")


def attach_inputs_outputs(traj, module, p, hook, data):
    """Add saved["input_<name>"] (S, 1) and saved["output_<name>"] (S, 1) to a Trajectory:
    the inputs the hook applies at each saved state (the hold over the next step) and the
    generated outputs there."""
    first, k = input_slots(module)
    n_out = getattr(module, "N_OUTPUTS", 0)
    if not (k or n_out):
        return traj
    rows = len(traj.t)
    u = np.tile(p[first:], (rows, 1))
    y = np.zeros((rows, n_out))
    pk = p.copy()
    outputs = unchecked(module.outputs) if n_out else None      # arrays made here, one call a row
    for r in range(rows):
        q, v = np.ascontiguousarray(traj.q[r]), np.ascontiguousarray(traj.v[r])
        if hook is not None:
            hook(data, float(traj.t[r]), q, v, pk)
            u[r] = pk[first:]
        if n_out:
            outputs(q, v, float(traj.t[r]), pk, y[r])
    for j, name in enumerate(module.PARAMS[first:]):
        traj.saved[f"input_{name}"] = u[:, j:j + 1].copy()
    for j, name in enumerate(getattr(module, "OUTPUTS", ())):
        traj.saved[f"output_{name}"] = y[:, j:j + 1].copy()
    return traj
