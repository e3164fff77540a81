"""The run loop of the fixed-step methods: run_loop (set-up, row 0), the stepping loop the glue
binds for a method (stepping_loop) and the steps it runs (steps).

The rules a method module follows are in lagrange_gen.steppers.methods; the buffers a run fills
are laid out in layout.py and written by output.py.

How the kernels reach the cores: ``kern`` is the generated module itself. numba types a module
as a compile-time constant with no runtime representation, so ``kern.dynamics(...)`` is a direct
call and ``kern.MASS_IS_CONSTANT`` a constant; likewise the stepping loop holds the method's
module as a closure constant and calls ``method.step``. Passing the dispatchers themselves as
values would make numba embed process-specific addresses ("dynamic globals") and refuse to cache
the glue; the stepping loop run_loop is given is a global of the glue once run_loop is inlined.
None of the functions taking ``kern`` is ``cache=True``: they are compiled into, and cached
with, each generated module's glue. ``run_loop`` is ``inline="always"`` (inlined at numba-IR
level into the glue): every separately compiled layer re-optimizes everything below it, about
0.5 s of compile time per layer, per method and per model (the stepping loop is one such layer,
paid for its speed: see stepping_loop).

Shapes: n coordinates; q, v, mom (n,); p (n_params,); extra (n_saved,) the method's saved
fields (empty for the unconstrained methods).
"""

import math

import numpy as np
from ...jit.cache import njit

from . import events, hermite, layout, work
from .layout import STAT_WORK
from .options import fast_loop
from .output import save_row, write_last, write_work
from .state_checks import check_state
from .status import NON_FINITE, OK


@njit(inline="always")
def run_loop(method, loop, kern, n_saved, n_event_fns, q0, v0, t0, h, n_steps, save_every, p,
             settings, out_t, out_q, out_v, out_stats, out_extra, out_last, out_events,
             control=None, control_data=None):
    """Integrate n_steps steps of size h from (q0, v0) at t0 without returning to Python.

    ``method`` is a stepper module (its workspace and prepare are called), ``loop`` its
    stepping loop on the generated module ``kern`` (stepping_loop: it runs the steps, the step
    inlined), or None to run them here (the portable glue: the step is called),
    ``kern`` the generated module, ``settings`` the method's settings record (method_spec.py),
    n_saved the width of the method's saved fields on this model and n_event_fns its number
    of event functions (N_EVENTS, or 1 for any number of them: only n_event_fns > 0 is read;
    the glue passes both as literals, which lets numba prune the event code of a model
    without events).
    Saves row 0 (initial state) and row k after step k * save_every, so the outputs need
    S = n_steps // save_every + 1 rows: out_t (S,), out_q (S, n), out_v (S, n), out_stats
    (S, N_STATS), out_extra (S, n_saved) (the method's saved fields, SPEC.saved), whose row 0
    also holds the initial values of those fields (element states, multipliers).
    out_stats[:, STAT_WORK] holds W, the work since t0 (work.py; 0 when kern.WORK is
    False), continued from out_stats[0, STAT_WORK]; an out_last one entry longer receives the
    final W in its last entry.
    out_last (2n + 3 + n_saved,) receives [t, q, v, Newton iterations since the last save,
    Newton residual, saved fields] (layout.py) of the final state, or on failure: of the state
    the failing step started from (Newton failure, singular mass) or of the offending state
    after it (NON_FINITE, UNSTABLE; also a non-finite energy at a saved state).
    Events (models with N_EVENTS > 0; see events.py): after each step the event functions are
    evaluated at the new state; a crossing is located on the step's Hermite interpolant
    (hermite.py) and recorded in out_events (E, 3 + 2n) as [t, event index, direction (+1
    rising, -1 falling), q, v] while there is room (E may be 0: further events are counted
    only). A terminal event ends the run inside step i: status OK, steps_done = i (steps i and
    later are not saved), out_last = [t of the event, q, v there (interpolated), iterations,
    residual, saved fields after step i]. With events, each step costs a copy of (q, v) (the
    start of the interpolant) and one evaluation of the event functions; the end accelerations
    and the root refinement only a step where some g changed sign. Without events the literal
    n_event_fns = 0 lets numba prune the event branches before typing them: no work, no
    allocation and no compile time (typing them would cost about 2.5 s per module).
    Inputs (lagrange_gen.run.control): ``control(control_data, t, q, v, p) -> changed``, a jitted
    function, writes the model's inputs (the trailing entries of p) from the state at the start
    of each step and at t0 (zero-order hold over a step), and the method's prepare runs again
    when they changed; None (the generated glue) prunes the calls.
    Returns (status, steps_done, n_events): steps_done = n_steps, or the index of the failing
    step on failure (or of the step in which a terminal event stopped the run), -1 when the
    initial state itself is refused (non-finite or past the bound, its energy non-finite, or
    the method's prepare failed); n_events: events located (rows of out_events written: at
    most E).
    """
    n = q0.shape[0]
    # The steps loop to kern.N_COORDS ("Loop bounds") and the kernels read the model's n
    # entries: a state of another size would be read past its end or partly ignored.
    if n != kern.N_COORDS or v0.shape[0] != n:
        raise ValueError("run_<method>: q0 and v0 need N_COORDS entries (the model's "
                         "coordinates)")
    if (out_extra.shape[1] != n_saved
            or out_last.shape[0] - layout.work_at(n, n_saved) not in (0, 1)):
        raise ValueError("run_<method>: out_extra needs n_saved columns and out_last "
                         "2 n + 3 + n_saved entries, or one more for W (n_saved = "
                         "SPEC.n_saved(n, m, ne))")
    # W, the work since t0 (work.py), continues from row 0 of out_stats (a run in chunks);
    # NaN there (an ensemble's fresh buffers) starts it at 0.
    W = out_stats[0, STAT_WORK]
    if W != W:
        W = 0.0
    q = q0.copy()
    v = v0.copy()
    mom = np.zeros(n)
    ws = method.workspace(kern, n)
    # The saved fields start from row 0 of out_extra, so a run continued in chunks carries them
    # over (element states; multipliers, also the next Newton guess).
    extra = np.zeros(out_extra.shape[1])
    for k in range(out_extra.shape[1]):
        extra[k] = out_extra[0, k]
    bound = settings.blowup_bound
    status = check_state(q, v, bound)
    if control is not None:
        control(control_data, t0, q, v, p)
    if status == OK:
        status = method.prepare(kern, q, v, mom, t0, p, settings, ws, extra)
    energy = kern.energy(q, v, t0, p)
    if status == OK and not math.isfinite(energy):
        status = NON_FINITE
    write_last(out_last, t0, q, v, 0.0, 0.0, extra)
    if status != OK:
        return status, -1, 0
    # row 0 as an int64, not the literal 0: numba compiles a separate save_row for
    # Literal[int](0) (0.12 s more in every first compile of a glue)
    save_row(np.int64(0), t0, q, v, energy, 0.0, 0.0, out_t, out_q, out_v, out_stats, extra,
          out_extra)
    out_stats[0, STAT_WORK] = W
    # The work workspace always exists (0-size arrays on a model without work): numba types the
    # branches on kern.WORK in any case, and the stepping loop takes it as an argument.
    ww = work.workspace(kern, n)
    P0, D0 = 0.0, 0.0
    if kern.WORK:
        P0, D0 = work.rate(kern, ww, q, v, t0, p)
    if n_event_fns > 0:
        ew = events.workspace(kern, n)
        iw = hermite.workspace(n)
        events.start(kern, ew, q, v, t0, p)
    else:           # (n_event_fns is a literal: numba prunes one branch and every use of these)
        ew = iw = None
    # (grouped: a call of 30 or more arguments compiles to CALL_FUNCTION_EX, which numba
    # cannot inline)
    outs = (out_t, out_q, out_v, out_stats, out_extra, out_last, out_events)
    aux = (ww, ew, iw, W, P0, D0, bound)
    if loop is None:        # the portable glue: the steps here, the step called
        return steps(method, kern, n_saved, n_event_fns, q, v, mom, ws, extra, t0, h, n_steps,
                     save_every, p, settings, outs, aux, control, control_data)
    return loop(kern, n_saved, n_event_fns, q, v, mom, ws, extra, t0, h, n_steps, save_every, p,
                settings, outs, aux, control, control_data)


def stepping_loop(method, kern, n_event_fns):
    """The stepping loop run_loop calls (its ``loop``) for the method module ``method`` on the
    generated module ``kern`` with n_event_fns event functions (the generated glue binds
    ``_loop_<method> = stepping_loop(<method module>, <this module>, N_EVENTS)``): run_loop's
    steps after its set-up (steps), with the method's step inlined (inline_step), compiled
    without reference counting. All three are closure constants of the loop, so that numba
    inlines the step and prunes the event branches of a model without events before it types
    them (numba prunes a branch on a constant, not on a literal argument).

    Why a function of its own: in run_loop, which allocates and so counts references, a step
    inlined pays for the count of every array it touches, and a step called pays for the call;
    here the step is inlined and nothing is counted (every method but explicit_euler steps
    faster; ns per step of every method: ``lagrange-gen bench steppers``, reports/steppers.md).
    The price is one more compiled layer in the glue's first compile (about a second; the time
    to a first step with numba's cache warm is in the same report). The portable glue (loop
    None in run_loop) keeps the steps inlined in run_loop and calls the step: it is compiled
    once per method for every model (jit/portable.py), on the first use of a method after an
    install, and a loop of its own would make that wait one compiled layer longer."""
    fixed_kern, fixed_events = kern, n_event_fns

    @fast_loop
    def loop(kern, n_saved, n_event_fns, q, v, mom, ws, extra, t0, h, n_steps, save_every, p,
             settings, outs, aux, control, control_data):
        return steps(method, fixed_kern, n_saved, fixed_events, q, v, mom, ws, extra, t0, h,
                     n_steps, save_every, p, settings, outs, aux, control, control_data)
    return loop


@njit(inline="always")
def steps(method, kern, n_saved, n_event_fns, q, v, mom, ws, extra, t0, h, n_steps, save_every,
          p, settings, outs, aux, control, control_data):
    """run_loop's n_steps steps from the state it set up (q, v, mom, ws, extra); outs = its
    output arrays, aux = (work and events workspaces, W, P0, D0, blowup bound). Returns
    run_loop's (status, steps_done, n_events)."""
    out_t, out_q, out_v, out_stats, out_extra, out_last, out_events = outs
    ww, ew, iw, W, P0, D0, bound = aux
    n = q.shape[0]
    n_events = 0
    iters_acc = 0.0
    resid_max = 0.0
    since = 0
    for i in range(n_steps):
        t = t0 + i * h       # not accumulated: no drift of t over millions of steps
        if n_event_fns > 0:
            hermite.begin(iw, q, v)
        if control is not None and control(control_data, t, q, v, p):
            # A changed input invalidates what prepare cached (verlet's acceleration).
            status = method.prepare(kern, q, v, mom, t, p, settings, ws, extra)
            if status != OK:
                write_last(out_last, t, q, v, iters_acc, 0.0, extra)
                return status, i, n_events
            if kern.WORK:
                # The power at the step's start with the input held over this step: the one
                # from the end of the last step had the old input, an O(h) error per step
                # that would cap the energy balance at order 1.
                P0, D0 = work.rate(kern, ww, q, v, t, p)
        if kern.WORK and kern.N_ELEMENTS > 0:
            work.elements_begin(kern, ww, q, p, extra)
        status, iters, resid = method.step(kern, q, v, mom, t, h, p, settings, ws, extra)
        iters_acc += iters
        resid_max = max(resid_max, resid)
        if status != OK:
            write_last(out_last, t, q, v, iters_acc, resid, extra)
            return status, i, n_events
        t_new = t0 + (i + 1) * h
        status = check_state(q, v, bound)
        if status != OK:
            write_last(out_last, t_new, q, v, iters_acc, resid, extra)
            return status, i, n_events
        if kern.WORK:
            P1, D1 = work.rate(kern, ww, q, v, t_new, p)
            W += work.increment(h, P0, D0, P1, D1)
            P0, D0 = P1, D1
            if kern.N_ELEMENTS > 0:      # (only element methods run on such a model: extra
                W += work.elements_increment(kern, ww, q, p, extra)   # holds their states)
        if n_event_fns > 0:
            if events.crossed(kern, ew, q, v, t_new, p):
                hermite.fit(kern, iw, t, t_new, q, v, p)
                n_events, stopped = events.locate(hermite, iw, kern, ew, p, t, t_new,
                                                  out_events, n_events)
                if stopped:
                    write_last(out_last, ew.stop[0], ew.q, ew.v, iters_acc, resid_max, extra)
                    write_work(out_last, n, n_saved, W)     # (W at the end of the step)
                    return OK, i, n_events
            events.advance(ew)
        since += 1
        if since == save_every:
            since = 0
            energy = kern.energy(q, v, t_new, p)
            if not math.isfinite(energy):      # e.g. log(x) at x <= 0: outside the model
                write_last(out_last, t_new, q, v, iters_acc, resid, extra)
                return NON_FINITE, i, n_events
            save_row((i + 1) // save_every, t_new, q, v, energy, iters_acc,
                  resid_max, out_t, out_q, out_v, out_stats, extra, out_extra)
            out_stats[(i + 1) // save_every, STAT_WORK] = W
            iters_acc = 0.0
            resid_max = 0.0
    write_last(out_last, t0 + n_steps * h, q, v, iters_acc, resid_max, extra)
    write_work(out_last, n, n_saved, W)
    return OK, n_steps, n_events
