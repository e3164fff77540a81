"""Drive a fixed-step method's glue from Python: chunks of steps, progress, failures, events.

simulate (run/simulate.py) checks the inputs and builds the Trajectory; this module runs the
generated ``run_<method>`` (codegen/glue.py, run_loop.run_loop) chunk by chunk so that a
progress bar can be shown, and turns a failure status into the exception naming the step
(run/failures.py). run/adaptive_driver.py is the same for the adaptive methods.
"""

from __future__ import annotations

import math
import sys
import time

import numpy as np

from .failures import raise_for_status
from ..jit import first_run, portable
from ..jit import portable as _portable
from ..jit.compile_notice import compiles, first_use_notice
from ..steppers.core import status as st
from ..steppers.core.layout import N_STATS, STAT_ITERS, events_size, last_size, read_last

#: Steps per call into the jitted loop (a multiple of save_every is used): large enough that the
#: Python overhead per chunk (a few microseconds) is negligible, small enough for a progress bar.
CHUNK_STEPS = 200_000

#: A portable run under simulate(jit="auto") compiles the specialized glue between chunks once
#: its projected remaining time passes this many seconds. Measured by ``lagrange-gen bench
#: speed`` (reports/speed.md): the specialized loop takes a third to a half off the step time
#: on the cart pendulum but little or nothing on the 16-link chain (where the kernels dominate),
#: and its compile costs 10 to 20 s: below a minute of remaining work it cannot pay for itself,
#: and on large models it may not pay at all (then it costs one compile in a run of minutes).
SPECIALIZE_AFTER_S = 60.0

#: The specialized compile of a model's kernels (numba, inlined into the loop) against their
#: native compile (jit/native.py): numba's front end costs several to tens of times LLVM's
#: (4x on the UR5's forward dynamics, 7x on a 12-link chain's, 28x on a 12-link inverse-dynamics
#: Jacobian), and the loop is compiled around them.
SPECIALIZED_PER_NATIVE_S = 10.0

#: What the specialized loop takes off a step of a large model (reports/speed.md: 3 to 6 % on
#: the 16-link chain): the gain that must pay for its compile.
SPECIALIZED_GAIN = 0.1

#: Steps of a run's first interpreted chunk (jit/interpreted.py), whose time projects the run's
#: interpreted time; later interpreted chunks double, up to CHUNK_STEPS.
PROBE_STEPS = 20

#: A compiled run of at least this many steps measures its step (seconds_per_step) and, when
#: it will take more than run.checks.LONG_RUN_S, says how long before it starts: below it, a run
#: takes a minute only at 6 ms a step or more.
ESTIMATE_AFTER_STEPS = 10_000

#: The measurement: PROBE_MIN_STEPS steps, doubled until they take PROBE_S seconds, never more
#: than PROBE_FRACTION of the run (nor PROBE_MIN_STEPS less); run on copies of the state.
PROBE_MIN_STEPS = 64
PROBE_S = 0.05
PROBE_FRACTION = 0.01

#: {method: seconds its runs spent interpreted in this process}: a program of many short runs
#: compiles once their sum would pass the compile (_worth_compiling).
_INTERPRETED_S: dict = {}

#: Rows of located events kept per run (steppers/core/events.py); more are counted, not stored.
EVENT_ROWS = 10_000


def n_steps_to(t0, t_end, h):
    """Whole steps to reach t_end; rounded up when (t_end - t0) / h is not an integer."""
    ratio = (t_end - t0) / h
    nearest = round(ratio)
    if abs(ratio - nearest) <= 1e-9 * max(1.0, abs(ratio)):
        return int(nearest)
    return int(math.ceil(ratio))


def allocate(rows, n, n_saved, initial, n_events):
    """Output arrays {t (S,), q, v (S, n), stats (S, N_STATS), extra (S, n_saved), events
    (E, 3 + 2 n)}; row 0 of extra holds the initial values of the method's saved fields
    (SPEC.saved: multipliers and residuals, or element states). E = EVENT_ROWS when the model
    has events, else 0."""
    out = dict(t=np.empty(rows), q=np.empty((rows, n)), v=np.empty((rows, n)),
               stats=np.zeros((rows, N_STATS)), extra=np.zeros((rows, n_saved)),
               events=np.zeros((EVENT_ROWS if n_events else 0, events_size(n))), n_events=0)
    if n_saved:
        out["extra"][0] = initial
    return out


def integrate_fixed(task, q, v, out, progress):
    """Run the glue chunk by chunk from (q, v), filling ``out``; sets out["last"], out["rows"]
    (rows used), out["steps"] (steps done: fewer than task.n_steps after a terminal event) and
    out["n_events"]. The glue is task.glue's choice (specialized or portable); a portable run
    under jit="auto" switches to the specialized glue between chunks once its projected
    remaining time passes SPECIALIZE_AFTER_S (task.ran records it). Returns (compile seconds,
    integration seconds). Under jit="auto" a first run of a method whose glue numba has compiled
    nowhere yet starts interpreted (_interpreted_glue). Raises the exception of a failure
    status (failures.raise_for_status)."""
    m, n, h, t0 = task.module, task.module.N_COORDS, task.h, task.t0
    last = np.zeros(last_size(n, out["extra"].shape[1], with_work=True))

    def args():
        return warm_up_args(q, v, t0, h, task.p, task.settings, out["extra"][:1].copy(),
                            last.copy(), out["events"][:0])

    label = f"run_{task.method} for {m.NAME}"
    run = ready_glue(task)
    compile_time = 0.0
    if run is None:
        first = args()
        run = _interpreted_glue(task, first)
        if run is None:
            run, compile_time = warm_up(lambda: task.glue(first), first, label)
            remember_glue(task, run)
            if task.hook is not None and task.ran == "specialized" and task.jit == "auto":
                _compile_controlled_for_next_time(task)
    if task.ran != "interpreted":
        announce_duration(task, run, q, v, task.t0, out, task.n_steps)
    chunk = max(1, CHUNK_STEPS // task.save_every) * task.save_every
    bar = ProgressBar(task.n_steps) if progress else None
    start = time.perf_counter()
    # Nothing should compile past the warm-up; if numba does (arguments of a type the
    # warm-up did not see), the notice says so instead of a silent pause.
    with first_use_notice(label):
        done, row, switch, compile_time = _chunks(task, run, q, v, out, last, args, label, bar,
                                                  chunk, start, compile_time)
    wall = time.perf_counter() - start - switch
    if bar:
        bar.close()
    out["last"], out["rows"], out["steps"] = last, row + 1, done
    return compile_time, wall


def _chunks(task, run, q, v, out, last, args, label, bar, chunk, start, compile_time):
    """The chunk loop of integrate_fixed (args(): the arguments of a warm-up call); returns
    (steps done, last row, seconds spent compiling between chunks, compile seconds). An
    interpreted run (task.ran "interpreted") goes on compiled once it is worth it
    (_worth_compiling) and no other compile of the glue is running (first_run.compile_running),
    or once the cache holds its glue (the background compile finished), or
    when Python cannot run a chunk (then that chunk runs again compiled)."""
    m, n, h, t0 = task.module, task.module.N_COORDS, task.h, task.t0
    done, row, switch = 0, 0, 0.0
    tier = task.ran
    # where the current tier began: (seconds since start, less switching; steps done)
    since = (0.0, 0)
    background = False
    while True:
        size = _interpreted_chunk(done, task.save_every) if tier == "interpreted" else chunk
        k = min(size, task.n_steps - done)
        rows = slice(row, row + k // task.save_every + 1)
        # Row `row` is the previous chunk's last save and this chunk's initial state: keep its
        # Newton statistics and saved fields, which belong to the steps before it (the method's
        # prepare may write the saved fields of its initial state there, e.g. multipliers).
        kept = out["stats"][row].copy()
        kept_extra = out["extra"][row].copy()
        found = min(out["n_events"], out["events"].shape[0])
        began = time.perf_counter()
        result = run(
            q, v, t0 + done * h, h, k, task.save_every, task.p, task.settings, out["t"][rows],
            out["q"][rows], out["v"][rows], out["stats"][rows], out["extra"][rows], last,
            out["events"][found:])
        if tier == "interpreted":
            _INTERPRETED_S[task.method] = (_INTERPRETED_S.get(task.method, 0.0)
                                           + time.perf_counter() - began)
            if result is None:      # Python cannot run these steps (jit.interpreted): compiled
                out["stats"][row], out["extra"][row] = kept, kept_extra
                run, seconds, tier = _compile_after_interpreted(task, args, label, done)
                compile_time += seconds
                switch += seconds
                announce_duration(task, run, q, v, t0 + done * h, out, task.n_steps - done)
                since = (time.perf_counter() - start - switch, done)
                continue
        code, steps, n_events = result
        out["n_events"] += n_events
        if row > 0:
            out["stats"][row, STAT_ITERS:] = kept[STAT_ITERS:]
            out["extra"][row] = kept_extra
        if code != st.OK:
            raise_for_status(code, m, task.method, done + steps + 1, task.n_steps, last,
                             task.max_iter, h, task.p)
        final = read_last(last, n, with_work=True)
        q, v = final.q.copy(), final.v.copy()
        if steps < k:                    # a terminal event stopped the run inside this chunk
            done += steps
            row += steps // task.save_every
            break
        done += k
        row += k // task.save_every
        if bar:
            bar.update(done)
        elapsed = time.perf_counter() - start - switch - since[0]
        if tier == "interpreted":
            # a compile of this glue running elsewhere (the background one): wait for it here,
            # interpreted, rather than compile the same glue beside it
            if done < task.n_steps and (portable.portable_cached(m, task.method) or (
                    _worth_compiling(task.method, elapsed, done - since[1], task.n_steps - done)
                    and not first_run.compile_running(task.method))):
                run, seconds, tier = _compile_after_interpreted(task, args, label, done)
                compile_time += seconds
                switch += seconds
                announce_duration(task, run, q, v, t0 + done * h, out, task.n_steps - done)
                since = (time.perf_counter() - start - switch, done)
            elif not background:
                background = True
                first_run.start_background_compile(m, task.method)
        if done >= task.n_steps:
            break
        if tier == "portable" and task.jit == "auto" and _worth_specializing(
                elapsed, done - since[1], task.n_steps - since[1],
                portable.native_compile_seconds(m, task.method)):
            run, seconds = warm_up(lambda: task.run, args(), label + ", specialized for this long run")
            compile_time += seconds
            switch += seconds
            task.ran = f"{task.ran}, then specialized from step {done}"
            tier = "specialized"
    return done, row, switch, compile_time


def announce_duration(task, run, q, v, t, out, remaining, stream=None):
    """Before ``remaining`` steps of a compiled run from (q, v) at t: when they are at least
    ESTIMATE_AFTER_STEPS and will take more than run.checks.LONG_RUN_S at the measured step
    (seconds_per_step), one line on ``stream`` (default stderr) says how long. Nothing is
    refused."""
    if remaining < ESTIMATE_AFTER_STEPS:
        return
    measured = seconds_per_step(task, run, q, v, out, remaining, t)
    if measured is None:
        return
    from .checks import long_run_line
    line = long_run_line(task.module.NAME, task.method, remaining, *measured)
    if line:
        stream = stream or sys.stderr
        stream.write(line + "\n")
        stream.flush()


def seconds_per_step(task, run, q, v, out, remaining=None, t=None):
    """(seconds per step, steps measured) of the compiled glue ``run`` from (q, v) at t (default
    task.t0): steps run on
    copies of the state into scratch rows (the run itself is untouched), PROBE_MIN_STEPS first,
    doubled while they take less than PROBE_S and stay within PROBE_FRACTION of ``remaining``
    (default task.n_steps). None when a measured call fails (the run itself will report it)."""
    remaining = task.n_steps if remaining is None else remaining
    t = task.t0 if t is None else t
    n, extra = q.shape[0], out["extra"]
    cap = max(PROBE_MIN_STEPS, int(PROBE_FRACTION * remaining))
    steps = PROBE_MIN_STEPS
    while True:
        scratch = np.zeros((2, extra.shape[1]))
        scratch[0] = extra[0]
        began = time.perf_counter()
        code, done, _ = run(q.copy(), v.copy(), t, task.h, steps, steps, task.p,
                            task.settings, np.empty(2), np.empty((2, n)), np.empty((2, n)),
                            np.zeros((2, N_STATS)), scratch,
                            np.zeros(last_size(n, extra.shape[1], with_work=True)),
                            out["events"][:0])
        seconds = time.perf_counter() - began
        if code != st.OK or done < 1:
            return None
        if seconds >= PROBE_S or 2 * steps > cap or done < steps:
            return seconds / done, done
        steps *= 2


def _interpreted_glue(task, args):
    """The interpreted runner (portable.interpreted_runner) when a run of task's kind should
    start interpreted, recorded in task.ran; else None. It should under jit="auto" when numba
    has neither the specialized glue nor the portable glue of the method in memory or in its
    cache (a first use after an install, or after the library changed): compiling one takes
    seconds to tens of seconds, a short run interpreted a fraction of a second."""
    if task.jit != "auto" or task.hook is not None or not first_run.interpreted_enabled() or \
            portable.unsupported():
        return None
    if portable.specialized_ready(task.run, args) or portable.portable_cached(task.module,
                                                                             task.method):
        return None
    task.ran = "interpreted"
    return portable.interpreted_runner(task.module, task.method)


def _compile_controlled_for_next_time(task):
    """After a controlled run under jit="auto" compiled its specialized loop (the portable
    controlled glue was not cached): start the background compile of the portable controlled
    glue (first_run), so that the next process runs any controller without compiling a loop."""
    if not portable.unsupported() and not portable.portable_cached(task.module, task.method,
                                                                   controlled=True):
        first_run.start_background_compile(task.module, task.method, controlled=True)


def _interpreted_chunk(done, save_every):
    """Steps of the next interpreted chunk: PROBE_STEPS first, then as many as are done, up to
    CHUNK_STEPS (a multiple of save_every)."""
    steps = min(max(PROBE_STEPS, done), CHUNK_STEPS)
    return max(1, steps // save_every) * save_every


def _worth_compiling(method, elapsed, done, remaining):
    """Whether an interpreted run that took ``elapsed`` seconds for ``done`` steps should
    compile now: the interpreted seconds of the method in this process (its earlier runs and
    this one) plus this run's projected remaining ones pass the compile expected
    (first_run.expected_compile_seconds)."""
    projected = elapsed * remaining / done if done > 0 else 0.0
    return (_INTERPRETED_S.get(method, 0.0) + projected
            > first_run.expected_compile_seconds(method))


def _compile_after_interpreted(task, args, label, done):
    """Compile (or load from numba's cache) the glue an interpreted run goes on with at step
    ``done`` as a first call would (task.glue); a compile of the portable glue records its CPU
    seconds for the next choice (first_run.record_compile_seconds). Returns (glue, seconds,
    the tier now running); task.ran says what ran."""
    cpu, count, first = time.process_time(), compiles(), args()
    run, seconds = warm_up(lambda: task.glue(first), first,
                           f"{label} after {done} interpreted steps")
    if task.ran == "portable" and compiles() > count:
        first_run.record_compile_seconds(task.method, time.process_time() - cpu)
    remember_glue(task, run)
    tier = task.ran
    task.ran = f"interpreted, then {tier} from step {done}"
    return run, seconds, tier


#: {task.ready_key(): (what ran, the portable glue or None, the specialized glue's overload
#: count then)}: the glue choice of each kind of run that has run in this process, so that a
#: warm call neither looks numba's cache up nor makes a warm-up call (ready_glue).
_READY: dict = {}


def ready_glue(task):
    """The glue of a run of the kind ``task`` is (task.ready_key) that already ran in this
    process, its choice recorded in task.ran; None when none did, or when a portable choice
    under jit="auto" should be made again because the specialized glue gained an overload."""
    entry = _READY.get(task.ready_key())
    if entry is None:
        return None
    ran, portable, overloads = entry
    if portable is None:
        task.ran = ran
        return task.run
    if task.jit == "auto" and len(getattr(task.run, "overloads", ())) != overloads:
        return None
    task.ran = ran
    if task.hook is not None:   # this run's data (control_params, samples), not the first's
        return _portable.controlled_runner(task.module, task.method, task.hook, task.data)
    return portable


def remember_glue(task, run):
    """Record the glue a warm-up chose for runs of task's kind (ready_glue)."""
    portable = None if task.ran == "specialized" else run
    _READY[task.ready_key()] = (task.ran, portable, len(getattr(task.run, "overloads", ())))


def warm_up_args(q, v, t0, h, p, settings, extra, last, events):
    """The arguments of a zero-step call of run_<method>: extra (1, n_saved) and last are
    scratch copies with the method's sizes."""
    n = q.shape[0]
    return (q, v, t0, h, 0, 1, p, settings, np.empty(1), np.empty((1, n)), np.empty((1, n)),
            np.empty((1, N_STATS)), extra, last, events)


def warm_up(glue, args, label="run"):
    """Compile (or load from numba's cache) the glue ``glue()`` returns (a choice that may
    compile the model's kernels, see portable.choose) with a zero-step call (warm_up_args), so
    that the measured wall time is integration only. label ("run_verlet for cart_pendulum")
    names the glue in the notice a call longer than a second prints (compile_notice). Returns
    (the glue, the seconds it took)."""
    start = time.perf_counter()
    with first_use_notice(label):
        run = glue()
        run(*args)
    return run, time.perf_counter() - start


def _worth_specializing(elapsed, done, n_steps, native_seconds=None):
    """Whether a portable run (jit="auto") that took ``elapsed`` seconds for ``done`` of its
    n_steps steps should compile the specialized glue now: its projected remaining time passes
    SPECIALIZE_AFTER_S, and, given the CPU seconds the model's native kernels took to compile
    (portable.native_compile_seconds; None: not known), the part of that time the specialized
    loop would save (SPECIALIZED_GAIN) passes what numba would take to compile it
    (SPECIALIZED_PER_NATIVE_S times the native seconds). A large model's kernels compiled by
    numba take minutes and gigabytes for a few per cent per step: then only a very long run
    compiles them."""
    if done <= 0:
        return False
    remaining = elapsed * (n_steps - done) / done
    if remaining <= SPECIALIZE_AFTER_S:
        return False
    if native_seconds is None:
        return True
    return remaining * SPECIALIZED_GAIN > SPECIALIZED_PER_NATIVE_S * native_seconds


class ProgressBar:
    """A one-line text bar on stderr, redrawn only when the percentage changes."""

    def __init__(self, total, width=40, stream=None):
        self.total, self.width, self.stream = max(total, 1), width, stream or sys.stderr
        self.shown = -1
        self.update(0)

    def update(self, done):
        pct = int(100 * min(done, self.total) / self.total)
        if pct != self.shown:
            self.shown = pct
            filled = self.width * pct // 100
            self.stream.write(f"\r[{'#' * filled}{' ' * (self.width - filled)}] {pct:3d}%")
            self.stream.flush()

    def close(self):
        self.stream.write("\n")
        self.stream.flush()
