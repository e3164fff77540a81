"""What simulate checks before it allocates or integrates; each failure is one SimulationError line.

* The scalar and vector arguments (``check_scalars``, ``vector``: shape (n,), finite).
* Element coefficients at the parameters of this run (``check_element_coefficients``): the model
  file checks them at its defaults only, and ``--param eta=-1`` or ``--freeze eta=0`` would
  otherwise run the return map with a non-positive threshold or stiffness into garbage.
  Likewise contact coefficients (``check_contact_coefficients``): restitution in [0, 1], friction
  >= 0 at this run's parameters (``params={"e": 1.5}`` would otherwise gain energy at each impact).
* The method's settings (``method_settings``): their types and the method's limits, and
  rtol < MAX_RTOL.
* The step count (``check_step_count``): at most MAX_STEPS steps; a run that will take more
  than LONG_RUN_S says so before it starts (``long_run_line``), it is not refused.
* The resolution of the time grid (``check_time_resolution``): the stepper evaluates forces at
  t0 + k h, and the driver saves those times; they must resolve h (TIME_RESOLUTION).
* Memory for the saved rows (``check_memory``), against the memory this process can still take
  now: MemAvailable, its cgroup's memory limit and RLIMIT_AS (run/memory.py).

Over 300 lines: twenty short checks, each with its one-line messages, kept in one module so
that simulate, ensemble and Stepper refuse the same inputs the same way.
"""

from __future__ import annotations

import math
import sys
import time

import numpy as np

from ..errors import SimulationError
from ..steppers.core.method_spec import make_settings
from . import memory
from .params import is_number

#: Largest step count simulate runs. At the fastest measured step (tens of ns, reports/steppers.md)
#: 1e12 steps are already more than half a day of integration; and the rounding error of a
#: fixed-step method grows up to about n_steps * 2.2e-16, i.e. 1e-4 relative at 1e12 steps, so
#: more steps of a smaller h cannot buy accuracy any more.
MAX_STEPS = 10**12

#: Largest spacing of float64 numbers near the run's times, as a fraction of h. The stepper
#: evaluates time-dependent forces at t0 + k h rounded to that spacing, so each time is off by at
#: most half of it: with TIME_RESOLUTION = 1e-6 a forcing resolved by the step (omega_f h <= 1)
#: is sampled with a phase error below 5e-7 rad, not accumulating (times are not summed), smaller
#: than the discretization error of a second-order method at omega h >= 1e-3, and saved times are
#: t0 + k h to six digits of h. (t0 = 1.7e9 has spacing 2.4e-7: steps below 0.24 are refused.)
#: Long runs may use more: near t = n h the spacing is up to n * 2.2e-16 * h, the relative
#: rounding that n steps accumulate in the state anyway, so a run from t0 = 0 is never refused.
TIME_RESOLUTION = 1e-6

#: Value columns simulate holds per saved row at its peak, besides 2 n (q, v) and 2 n_saved
#: (out_extra and its copy): t, the three out_stats columns, and the energy, newton_iters and
#: newton_residual copies made for the Trajectory.
_ROW_COLUMNS = 7


def check_scalars(h, t0, t_end, save_every):
    """simulate's scalar arguments: finite numbers (not bools), h > 0, t_end >= t0, save_every a
    positive integer. (A method's own settings are checked by steppers.spec.make_settings.)"""
    for name, value in (("h", h), ("t0", t0), ("t_end", t_end)):
        if not is_number(value) or not math.isfinite(value):
            raise SimulationError(f"{name} must be a finite number, got {value!r}")
    if h <= 0:
        raise SimulationError(f"step size h must be > 0, got {h}")
    if t_end < t0:
        raise SimulationError(f"t_end = {t_end} is before t0 = {t0}")
    if (not is_number(save_every) or not math.isfinite(save_every) or int(save_every) != save_every
            or save_every < 1):
        raise SimulationError(f"save_every must be a positive integer, got {save_every!r}")


def check_t_eval(t_eval, t0, t_end):
    """t_eval: finite, strictly increasing times within [t0, t_end]."""
    try:
        times = np.asarray(t_eval, dtype=np.float64)
    except (TypeError, ValueError):
        raise SimulationError(f"t_eval must be a sequence of numbers, got {t_eval!r}") from None
    if times.ndim != 1 or not len(times) or not np.all(np.isfinite(times)):
        raise SimulationError("t_eval must be a non-empty 1-d sequence of finite times")
    if np.any(np.diff(times) <= 0):
        k = int(np.argmax(np.diff(times) <= 0))
        raise SimulationError(f"t_eval must be strictly increasing: t_eval[{k + 1}] = "
                              f"{times[k + 1]:g} after {times[k]:g}")
    if times[0] < t0 or times[-1] > t_end:
        raise SimulationError(f"t_eval must lie in [t0, t_end] = [{t0:g}, {t_end:g}], got "
                              f"[{times[0]:g}, {times[-1]:g}]")


def vector(name, value, n, coords):
    """value as a float64 vector (n,) (zeros when None), or a SimulationError naming ``name``:
    a sequence of n finite numbers in one dimension (a (1, 2) or (2, 1) q0 is not flattened:
    the message gives the shape meant and the coordinates)."""
    if value is None:
        return np.zeros(n)
    try:
        # a copy: the caller's array stays untouched, and the glue always sees a writable
        # C-contiguous float64 array (one numba type for every call)
        arr = np.array(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise SimulationError(f"{name} must be a sequence of {n} numbers, got {value!r}") from None
    if arr.ndim != 1:
        raise SimulationError(f"{name} must have shape ({n},) ({', '.join(coords)}), got an "
                              f"array of shape {arr.shape}")
    if arr.shape[0] != n:
        raise SimulationError(f"{name} has {arr.shape[0]} entries but the model has {n} "
                              f"coordinates ({', '.join(coords)})")
    # A finite sum has finite terms (a NaN or an infinity makes the sum NaN or infinite): one
    # sum instead of two numpy calls on the common finite vector; a sum that overflows is
    # looked at entry by entry. In Python floats, which overflow without numpy's warning.
    if not math.isfinite(sum(arr.tolist())) and not np.all(np.isfinite(arr)):
        raise SimulationError(f"{name} contains a non-finite value: {arr.tolist()}")
    return arr


#: A constrained run whose max|Phi| passes this fraction of max(1, max|q|) warns: a method
#: that keeps the constraints (rattle, index1) holds them to its Newton tolerance and spook's
#: drift stays within a few times h^2 (6e-4 on the Cartesian pendulum at h = 0.01, 0.05 at
#: h = 0.1); 6.3 on x^2 + y^2 = 1 - t past t = 1 means the constraints have no solution there.
CONSTRAINT_WARNING = 0.01


def constraint_violation(model, method, t, q, phi):
    """The warning (one line) for a constrained run whose max|Phi| (S,) over the saved rows
    passes CONSTRAINT_WARNING * max(1, max|q|) (q (S, n), times t (S,)), naming the first time it
    does; None otherwise."""
    if phi is None or not len(phi):
        return None
    phi = np.asarray(phi, dtype=float).reshape(len(phi), -1).max(axis=1)
    bound = CONSTRAINT_WARNING * max(1.0, float(np.nanmax(np.abs(q))) if np.size(q) else 1.0)
    over = np.flatnonzero(~(phi <= bound))
    if not over.size:
        return None
    first = over[0]
    return (f"{model}, {method}: the constraints are violated by max|Phi| = {np.nanmax(phi):.3g} "
            f"(above {bound:.3g} from t = {t[first]:g}): they may have no solution there (a "
            f"time-dependent constraint that becomes infeasible), or h is too large")


def check_events_at_start(module, q, v, t0, p):
    """Refuse a run whose event functions are not finite at the initial state (q, v (n,), t0):
    NaN compares false with everything, so such an event would never fire."""
    names = tuple(getattr(module, "EVENT_NAMES", ()))
    if not names:
        return
    values = np.empty(len(names))
    module.events(np.ascontiguousarray(q, dtype=np.float64), np.ascontiguousarray(v, dtype=np.float64),
                  float(t0), np.ascontiguousarray(p, dtype=np.float64), values)
    for name, value in zip(names, values.tolist()):
        if not math.isfinite(value):
            raise SimulationError(f"{module.NAME}: event {name} is {value} at the initial state "
                                  f"(t0 = {t0:g}, q0 = {np.asarray(q).tolist()}): it would never "
                                  f"fire; check where its function is defined")


def check_element_coefficients(module, p):
    """Refuse a non-positive (or non-finite) stiffness, threshold or friction bound of a
    nonsmooth element at the parameter vector p (n_params,), naming the element and the
    parameters the coefficient depends on (found by perturbing each parameter)."""
    ne = getattr(module, "N_ELEMENTS", 0)
    if not ne:
        return
    coef = element_coefficients(module, p)
    labels = ({0: "stiffness", 1: "threshold"}, {0: "friction bound"})
    for e in range(ne):
        kind = int(coef[e, 2])
        for col, label in labels[kind].items():
            value = coef[e, col]
            if math.isfinite(value) and value > 0:
                continue
            raise SimulationError(
                f"{module.NAME}: element {module.ELEMENTS[e]!r}: {label} = {value:g} must be a "
                f"finite number > 0; "
                f"{_coefficient_source(module, p, element_coefficients, coef, e, col)}")


def element_coefficients(module, p):
    """coef (ne, 3) of the generated ``elements`` kernel: (stiffness, threshold, 0) or
    (bound, 0, 1); they depend on parameters only (model/model.py checks that)."""
    ne, n = module.N_ELEMENTS, module.N_COORDS
    s, G, coef = np.empty(ne), np.empty((ne, n)), np.empty((ne, 3))
    module.elements(np.zeros(n), np.ascontiguousarray(p, dtype=np.float64), s, G, coef)
    return coef


def check_contact_coefficients(module, p, q=None):
    """Refuse a restitution outside [0, 1] or a negative (or non-finite) friction of a unilateral
    contact at the parameter vector p (n_params,), naming the contact and the parameters the
    coefficient depends on. (The model file checks them at the defaults only.) q (n,): where
    the kernel is evaluated (default zeros; the initial state keeps the gaps' Jacobians defined)."""
    if not getattr(module, "N_CONTACTS", 0):
        return
    where = np.zeros(module.N_COORDS) if q is None else q
    coef = contact_coefficients(module, p, where)
    for c in range(module.N_CONTACTS):
        for col, label, rule, ok in ((0, "restitution", "must be in [0, 1]", lambda x: 0 <= x <= 1),
                                     (1, "friction", "must be >= 0", lambda x: x >= 0)):
            value = coef[c, col]
            if math.isfinite(value) and ok(value):
                continue
            source = _coefficient_source(module, p, lambda m, p: contact_coefficients(m, p, where),
                                         coef, c, col)
            raise SimulationError(f"{module.NAME}: contact {module.CONTACTS[c]!r}: {label} = "
                                  f"{value:g} {rule}; {source}")


def contact_coefficients(module, p, q):
    """coef (c, 2) = (restitution, friction) of the generated ``contacts`` kernel at q (n,);
    they depend on parameters only (model/contacts.py checks that)."""
    nc, n = module.N_CONTACTS, module.N_COORDS
    gap, WN, WT, coef = np.empty(nc), np.empty((nc, n)), np.empty((2 * nc, n)), np.empty((nc, 2))
    module.contacts(np.ascontiguousarray(q, dtype=np.float64), 0.0, np.ascontiguousarray(p, dtype=np.float64), gap, WN, WT,
                    coef)
    return coef


def _coefficient_source(module, p, coefficients, coef, e, col):
    """'it depends on eta = -1 (...)': the parameters whose change moves coef[e, col];
    coefficients(module, p) gives coef."""
    used = []
    for j, name in enumerate(module.PARAMS):
        trial = np.array(p, dtype=np.float64)
        trial[j] += 0.5 * max(1.0, abs(trial[j]))
        moved = coefficients(module, trial)[e, col]
        if not (moved == coef[e, col] or (math.isnan(moved) and math.isnan(coef[e, col]))):
            used.append(f"{name} = {p[j]:g}")
    frozen = getattr(module, "FROZEN", None) or {}
    if used:
        return (f"it depends on {', '.join(used)}: pass other values (params={{...}} or "
                f"--param NAME=VALUE)")
    if frozen:
        values = ", ".join(f"{k} = {v:g}" for k, v in frozen.items())
        return (f"it comes from the frozen parameters ({values}): regenerate with other "
                f"--freeze values")
    return "it is a constant of the model file"


#: rtol at or above this is refused: a local error allowed as large as the solution itself
#: controls nothing. (The lower limits are the method's own, in its SPEC.limits: rtol >= 100
#: eps, the bound below which scipy's solve_ivp raises rtol with a warning; atol > 0. scipy
#: sets no upper limit on rtol, nor does Hairer's DOP853; rtol >= 1 accepts every step, which
#: only a run meaning fixed steps asks for: it is taken with a warning.)
MAX_RTOL = 1.0


def method_settings(spec, given):
    """The method's settings record from simulate's keywords (method_spec.make_settings: each
    checked against its type and the method's limits); rtol >= MAX_RTOL is taken with one
    warning line: it accepts every step, which is what a run meaning fixed steps of an adaptive
    method asks for (with h_max = h; the order tests of dop853 do), and never what a run meaning
    an accuracy does."""
    settings = make_settings(spec, given)
    rtol = getattr(settings, "rtol", None)
    if rtol is not None and not rtol < MAX_RTOL:
        import warnings
        warnings.warn(f"rtol = {given.get('rtol')!r} >= {MAX_RTOL:g} controls nothing (a "
                      f"relative error as large as the solution): every step is accepted, its "
                      f"size bounded by h_max only", RuntimeWarning, stacklevel=3)
    return settings


#: A fixed-step run whose estimated time passes this many seconds says so before it starts
#: (long_run_line; the estimate: run/fixed_driver.seconds_per_step).
LONG_RUN_S = 60.0


def long_run_line(model, method, n_steps, seconds_per_step, measured_steps):
    """The line (lagrange-gen: ...) telling how long n_steps steps at ``seconds_per_step`` (as
    measured on ``measured_steps`` steps) will take, when that passes LONG_RUN_S; else None."""
    seconds = n_steps * seconds_per_step
    if not seconds > LONG_RUN_S:
        return None
    return (f"lagrange-gen: {model}, {method}: {n_steps:.3g} steps at "
            f"{_per_step(seconds_per_step)} per step (measured on {measured_steps} steps) will "
            f"take {_duration(seconds)}; a larger h or a shorter run takes less (progress=True "
            f"or --progress shows a bar)")


def _per_step(seconds):
    for unit, scale in (("s", 1.0), ("ms", 1e-3), ("us", 1e-6)):
        if seconds >= scale:
            return f"{seconds / scale:.3g} {unit}"
    return f"{seconds / 1e-9:.3g} ns"


def _duration(seconds):
    """'about 3.3 minutes', 'about 5 hours', ... (two significant digits)."""
    for unit, scale in (("years", 365.25 * 86400), ("days", 86400.0), ("hours", 3600.0),
                        ("minutes", 60.0)):
        if seconds >= scale:
            value = float(f"{seconds / scale:.2g}")
            text = f"{value:.0f}" if value >= 10 or value == int(value) else f"{value:g}"
            return f"about {text} {unit[:-1] if text == '1' else unit}"
    return f"about {seconds:.2g} seconds"


def check_step_count(t0, t_end, h):
    """Refuse more than MAX_STEPS steps (also an overflowing (t_end - t0) / h) before anything
    is sized from the step count."""
    steps = (t_end - t0) / h
    if steps > MAX_STEPS:
        raise SimulationError(
            f"t0 = {t0:g} to t_end = {t_end:g} with h = {h:g} is {steps:.3g} steps, more than "
            f"the {MAX_STEPS:.0e} simulate runs (beyond that rounding errors, about n_steps * "
            f"2.2e-16, outgrow any gain from a smaller h); use a larger h or a shorter run")


def step_past_end(model, method, t0, t_end, h, n_steps):
    """The warning (one line) for a step longer than the whole run: the run's only step ends
    past t_end (h = 1 with t_end = 0.5 ends at t = 1); None otherwise. (A step that divides the
    span unevenly overshoots by less than h, as simulate documents.)"""
    if not (t_end > t0 and h > t_end - t0):
        return None
    return (f"{model}, {method}: the step h = {h:g} is longer than the run (t_end - t0 = "
            f"{t_end - t0:g}): it ends at t = {t0 + n_steps * h:g}, past t_end = {t_end:g}; "
            f"use h <= {t_end - t0:g}")


def check_time_resolution(t0, t_last, h, n_steps):
    """Refuse a run whose times t0 + k h (up to t_last) cannot be told apart to
    max(TIME_RESOLUTION, 2 n_steps eps) h in float64 (e.g. t0 = 1.7e9 with h = 1e-7: saved
    times repeat, forces see frozen times)."""
    biggest = max(abs(t0), abs(t_last))
    spacing = math.ulp(biggest)              # np.spacing of a float, without numpy's overhead
    allowed = max(TIME_RESOLUTION, 2 * n_steps * sys.float_info.epsilon) * h
    if spacing > allowed:
        raise SimulationError(
            f"t0 = {t0:g} with h = {h:g}: float64 numbers near |t| = {biggest:g} are "
            f"{spacing:.3g} apart, more than {allowed / h:.3g} h, so t + h cannot be told from t "
            f"to the precision a step needs; shift the time origin (t0 near 0) or use "
            f"h >= {spacing / TIME_RESOLUTION:.3g}")


def available_memory():
    """Bytes a new allocation can take now: the least of MemAvailable, the cgroup memory limits
    and RLIMIT_AS (run/memory.py); None when none is known."""
    return memory.available_memory()


def _binding_bound(free):
    """" (the cgroup limit (PATH))" when a process limit, not the machine's MemAvailable, is what
    leaves ``free`` bytes; else ""."""
    bounds = memory.memory_bounds()
    if not bounds or free is None:
        return ""
    name = min(bounds, key=bounds.get)
    if name == "MemAvailable" or abs(bounds[name] - free) > 0.05 * free + 2**20:
        return ""
    return f" (the {name})"


def saved_rows(n_steps, save_every):
    """Rows of a run: the initial state, one per save_every steps, and the final state when it
    does not fall on a save."""
    return n_steps // save_every + 1 + (1 if n_steps % save_every else 0)


def saved_bytes(rows, n, n_saved):
    """Bytes simulate holds at its peak for ``rows`` saved states of n coordinates and n_saved
    extra values per row (see _ROW_COLUMNS)."""
    return rows * 8 * (2 * n + 2 * n_saved + _ROW_COLUMNS)


#: check_memory reads the available memory (a dozen /proc and cgroup files, most of a short
#: run's cost) again only for a need above SMALL_FRACTION of the last reading or when that
#: reading is older than REREAD_AFTER_S: a run of many short simulate calls checks once a second.
SMALL_FRACTION = 0.01
REREAD_AFTER_S = 1.0
#: [the available_memory read (a test may replace it), when (time.monotonic), bytes or None]
_LAST_READING = [None, 0.0, None]


def check_memory(model, n_steps, save_every, n, n_saved, need=None, what=None):
    """Refuse, before allocating, a run whose saved rows do not fit in the available memory,
    suggesting the save_every that would leave half of it free. need: the bytes the caller
    holds at its peak (default saved_bytes of one run), what: the run named in the message
    (default "saving S states (N steps, save_every = K)")."""
    rows = saved_rows(n_steps, save_every)
    need = saved_bytes(rows, n, n_saved) if need is None else need
    reader, stamp, seen = _LAST_READING
    now = time.monotonic()
    if (reader is available_memory and seen is not None and now - stamp < REREAD_AFTER_S
            and need <= SMALL_FRACTION * seen):
        return
    free = available_memory()
    _LAST_READING[:] = [available_memory, now, free]
    if free is None or need <= free:
        return
    suggest = save_every * math.ceil(need / (0.5 * free))
    what = what or f"saving {rows} states ({n_steps} steps, save_every = {save_every})"
    raise SimulationError(
        f"{model}: {what} needs {_gb(need)} of memory and {_gb(free)} is available"
        f"{_binding_bound(free)}; use "
        f"save_every >= {suggest} (--save-every {suggest})")


def _gb(nbytes):
    return f"{nbytes / 1e9:.3g} GB"
