"""Rules and shared machinery of the stepper library.

The rules every method module (``steppers/methods/<method>.py``) follows:

* One integrator per module, with a module docstring stating the scheme, its order and the
  properties the tests check.
* A declaration ``SPEC = method_spec.Spec(...)`` at the end of the module (see method_spec.py): name, order,
  family, the models it applies to, its typed settings record, the kernels it calls and the
  named fields it saves per output row.
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
* No ``run`` function: the generated glue ``run_<method>`` calls ``run_loop`` with the method's
  module and the stepping loop it binds for it (``stepping_loop``; see codegen/glue.py for why the
  glue exists); adaptive methods have their own loop (adaptive.py) and their own set of
  functions (see there). ``step`` is declared ``@njit(inline=inline_step, **FAST)``.
* No allocation per step: the workspace is allocated once per run and passed to ``step``.
* Failures are status codes (lagrange_gen.steppers.core.status), never garbage and never exceptions.

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

Speed: everything called once or more per step is compiled with jit.NO_REFCOUNT (numba's switch
for "no reference counting"; none of these functions allocates). With reference counting on,
numba increments and decrements an atomic counter for every array argument of every call and
every array view that its pruning pass cannot prove redundant, which is most of them in
functions with loops and early returns: on the cart pendulum that was half of the run time of
the Newton methods (perf: NRT_incref/NRT_decref), and a 2 x 2 LU solve through calls cost 85 ns
against 29 ns without. Only ``run_loop`` allocates (once per run) and keeps reference counting;
the steps run in the stepping loop it calls (stepping_loop), which does not.

Loop bounds: the fixed-step methods' per-step loops over the coordinates (the steps, the
Newton loops of newton.py, explicit_rk's stages, and the helpers below that take an ``n``) run
to ``kern.N_COORDS``, not to an array's shape. In a generated module's glue that is a
compile-time constant, so LLVM unrolls the loops of a small model into straight-line code (the
2 x 2 cart pendulum) and knows every trip count of a larger one; in the portable glue it is a
field of the kernel table, a run-time value like the shape. run_loop refuses a state of another
length. Measured on the cart pendulum (best of 7 runs of 1e5 steps, taskset to one core,
/tmp/port.py in the issue-13 note), ns per step: symplectic_euler 97 -> 62, verlet 173 -> 105,
composition 659 -> 362, midpoint 138 -> 129, implicit_euler 100 -> 84 (explicit_euler and rk4
unchanged). Methods whose Newton unknowns are not the coordinates (the constrained ones) pass
x.shape[0].

Shapes: n coordinates; q, v, mom (n,); p (n_params,); extra (n_saved,) the method's saved
fields (empty for the unconstrained methods).
"""

import math

import numpy as np
from ...jit import NO_REFCOUNT, njit

from . import linalg
from .status import NON_FINITE, OK, SINGULAR_MASS, SINGULAR_NEWTON, UNSTABLE

#: numba options of every function on the per-step path (see the module docstring).
#: error_model="numpy": a division by zero gives inf/NaN (caught as NON_FINITE by check_state or
#: failed_solve_status) instead of raising ZeroDivisionError from inside the jitted loop, and
#: numba drops its zero-divisor checks on every division.
FAST = dict(**NO_REFCOUNT, error_model="numpy")

# Columns of ``out_stats`` (n_saves, N_STATS), one row per saved state.
STAT_ENERGY = 0     # E = T + V at the saved state
STAT_ITERS = 1      # Newton iterations summed over the steps since the previous save
STAT_RESIDUAL = 2   # largest Newton residual (max norm, last iterate of a step) over those steps
STAT_WORK = 3       # W, the work of non-conservative forces and explicit time since t0 (work.py)
N_STATS = 4

def inline_step(expr, caller_ir, callee_ir):
    """numba inline cost model (``@njit(inline=inline_step)``) of every fixed-step method's
    ``step``: inlined into the loops compiled without reference counting (declared with
    fast_loop: the stepping loop of a generated module's glue, stepping_loop, and the step
    API's), called from everywhere else. Inlined into a reference-counted loop (the portable
    glue's run_loop), rk4's step went from 100 to 170 ns on the cart pendulum (every array the
    step touches is counted there)."""
    return getattr(caller_ir.func_id.func, "inlines_step", False)


def fast_loop(fn):
    """``fn`` compiled without reference counting (FAST), marked as a loop that inline_step
    inlines a method's step into."""
    fn.inlines_step = True
    return njit(**FAST)(fn)


@njit(**FAST)
def explicit_path(kern, settings):
    """True when a partitioned method may skip Newton: the model has constant H and
    velocity-free forces (generated flags) and settings.newton_always is off."""
    return kern.MASS_IS_CONSTANT and kern.FORCES_VELOCITY_FREE and not settings.newton_always


@njit(cache=True, **FAST)
def max_abs(x):
    """max |x_i| of a vector (n,); NaN propagates (returns NaN)."""
    return max_abs_of(x, x.shape[0])


@njit(inline="always")
def max_abs_of(x, n):
    """max_abs of x[:n], inlined (n from kern.N_COORDS: see "Loop bounds" above)."""
    m = 0.0
    for i in range(n):
        a = abs(x[i])
        if a > m or a != a:
            m = a
    return m


@njit(cache=True, **FAST)
def increment_small(dx, x, tol):
    """Newton stopping test on the increment, relative to the size of the unknown."""
    return max_abs(dx) <= tol * max(1.0, max_abs(x))


@njit(cache=True, **FAST)
def increment_converged(d, xmax, prev, tol):
    """The stopping rule of newton_converged on precomputed norms: d = max|dx| of this
    iteration, xmax = max|x| after the update, prev = d of the previous iteration (0 on the
    first)."""
    size = tol * max(1.0, xmax)
    if d <= size:
        return True
    if prev > 0.0:
        theta = d / prev
        if theta < 1.0 and theta / (1.0 - theta) * d <= size:
            return True
    return False


@njit(inline="always")
def newton_converged(dx, x, prev, tol, n):
    """Newton stopping test after the update x += dx (both (n,); n passed, see "Loop bounds");
    returns (converged, max|dx|).

    ``prev`` is max|dx| of the previous iteration (0 on the first). Converged when the increment
    is small relative to the unknown, max|dx| <= tol max(1, max|x|), or when the observed
    contraction theta = |dx| / |prev| < 1 bounds the error left in x by theta / (1 - theta) |dx|
    below that (Hairer-Wanner, Solving ODEs II, sec. IV.8): in the quadratic regime this saves
    the last iteration, which would only confirm convergence."""
    d = max_abs_of(dx, n)
    return increment_converged(d, max_abs_of(x, n), prev, tol), d


@njit(cache=True, **FAST)
def copy_into(dst, src):
    for i in range(src.shape[0]):
        dst[i] = src[i]


@njit(inline="always")
def matvec(A, x, out, n):
    """out = A x for A (n, n), x (n,); n passed (kern.N_COORDS: see "Loop bounds" above)."""
    for i in range(n):
        s = 0.0
        for j in range(n):
            s += A[i, j] * x[j]
        out[i] = s


# lagrange_gen.steppers.core.linalg is compiled without reference counting too: plain calls.
_cholesky = linalg.cholesky_inplace
_cholesky_solve = linalg.cholesky_solve_inplace
_lu_solve_system = linalg.lu_solve_system


@njit(**FAST)
def mass_solve(H, b):
    """Overwrite b (n,) by H^-1 b with H (n, n) SPD, factored in place. False if singular."""
    if not _cholesky(H):
        return False
    _cholesky_solve(H, b)
    return True


@njit(cache=True, **FAST)
def failed_solve_status(A):
    """Status of a Newton matrix A (N, N) whose factorization just failed: NON_FINITE when A
    holds NaN or inf (non-finite arithmetic in the kernels, e.g. 1/x at x = 0), else
    SINGULAR_NEWTON. The factorizations return before touching A when its scale is not finite,
    and eliminating a NaN or inf leaves NaN behind, so A still shows which case it was."""
    for i in range(A.shape[0]):
        for j in range(A.shape[1]):
            if not math.isfinite(A[i, j]):
                return NON_FINITE
    return SINGULAR_NEWTON


@njit(**FAST)
def newton_solve(A, piv, b, scratch):
    """Overwrite b by A^-1 b for a Newton matrix A (general: Gaussian elimination with partial
    pivoting applied to b as it goes, A left holding its LU factors). Returns OK,
    SINGULAR_NEWTON, or NON_FINITE (see failed_solve_status). scratch (n,) is not needed by
    the one-pass elimination; it stays in the signature of the Newton loop's solve."""
    if not _lu_solve_system(A, piv, b):
        return failed_solve_status(A)
    return OK


@njit(inline="always")
def factor_mass(H, A, piv, n):
    """A (n, n) <- the factors of the SPD mass matrix H in lu_solve_inplace's layout (Cholesky,
    rewritten by linalg.cholesky_as_lu; piv the identity), H unchanged. One factorization then
    serves v = H^-1 (p - b) and the first Newton matrix of the partitioned methods' next kick
    and drift (partitioned.py). False when H is not numerically positive definite. n = H's
    size, passed (kern.N_COORDS: see "Loop bounds" above)."""
    for i in range(n):
        for j in range(n):
            A[i, j] = H[i, j]
    if not _cholesky(A):
        return False
    linalg.cholesky_as_lu(A, piv, n)
    return True


@njit(inline="always")
def velocity_from_factors(kern, q, mom, t, p, A, piv, v, scratch):
    """v = H(q, t)^-1 (mom - b(q, t)) (n,) from H's factors in A, piv (factor_mass)."""
    for i in range(kern.N_COORDS):
        v[i] = mom[i]
    subtract_transport(kern, q, t, p, v)
    linalg.lu_solve_inplace(A, piv, v, scratch)


@njit(**FAST)
def accel(kern, q, v, t, p, H, a):
    """a = H(q)^-1 rhs(q, v, t) (n,), H (n, n) workspace; OK or SINGULAR_MASS.

    The generated forward_dynamics (compiled without reference counting) uses the Cholesky factor
    computed at import when H is constant and its parameters have their defaults."""
    return kern.forward_dynamics(q, v, t, p, H, a)


@njit(**FAST)
def velocity_from_momentum(kern, q, mom, t, p, H, v):
    """v = H(q, t)^-1 (mom - b(q, t)) (the inverse Legendre transform; b = 0 unless T has a
    term T1 = b . v, kern.TRANSPORT). Returns OK or SINGULAR_MASS."""
    kern.mass_matrix(q, t, p, H)
    copy_into(v, mom)
    subtract_transport(kern, q, t, p, v)
    return OK if mass_solve(H, v) else SINGULAR_MASS


@njit(**FAST)
def subtract_transport(kern, q, t, p, x):
    """x (n,) <- x - b(q, t) on a model with T1 = b . v (kern.TRANSPORT; nothing otherwise). The
    generated ``transport`` adds b, so x is negated around it."""
    if kern.TRANSPORT:
        for i in range(x.shape[0]):
            x[i] = -x[i]
        kern.transport(q, t, p, x)
        for i in range(x.shape[0]):
            x[i] = -x[i]


@njit(**FAST)
def momentum_from_velocity(kern, q, v, t, p, H, mom):
    """mom = H(q, t) v + b(q, t) (the Legendre transform, canonical momentum dL/dv)."""
    kern.mass_matrix(q, t, p, H)
    matvec(H, v, mom, kern.N_COORDS)
    if kern.TRANSPORT:
        kern.transport(q, t, p, mom)


@njit(cache=True, **FAST)
def check_state(q, v, bound):
    """NON_FINITE if any entry is NaN/inf, UNSTABLE if one exceeds bound, else OK.

    Runs after every step: one comparison per entry (NaN fails it too), the failing case sorted
    out by _classify. Against max_abs over q and v (a branch on NaN per entry) that took 26.2 ->
    23.3 ns per explicit Euler step on the cart pendulum (best of 15 runs of 2e5 steps)."""
    limit = min(bound, _LARGEST)       # a bound of inf must still stop at inf
    for i in range(q.shape[0]):
        if not (abs(q[i]) <= limit and abs(v[i]) <= limit):
            return _classify(q, v)
    return OK


_LARGEST = np.finfo(np.float64).max


@njit(cache=True, **FAST)
def _classify(q, v):
    """check_state's verdict on a state that failed its comparison: NON_FINITE when an entry is
    NaN or inf, else UNSTABLE. (Each entry is tested: max(max_abs(q), max_abs(v)) drops a NaN of
    v behind a finite max of q, since max(a, NaN) is a.)"""
    for i in range(q.shape[0]):
        if not (math.isfinite(q[i]) and math.isfinite(v[i])):
            return NON_FINITE
    return UNSTABLE


@njit(cache=True, **FAST)
def save_row(row, t, q, v, energy, iters, resid, out_t, out_q, out_v, out_stats, extra, out_extra):
    out_t[row] = t
    for i in range(q.shape[0]):
        out_q[row, i] = q[i]
        out_v[row, i] = v[i]
    out_stats[row, STAT_ENERGY] = energy
    out_stats[row, STAT_ITERS] = iters
    out_stats[row, STAT_RESIDUAL] = resid
    for k in range(min(extra.shape[0], out_extra.shape[1])):
        out_extra[row, k] = extra[k]


@njit(cache=True, **FAST)
def write_last(out_last, t, q, v, iters, resid, extra):
    n = q.shape[0]
    out_last[0] = t
    for i in range(n):
        out_last[1 + i] = q[i]
        out_last[1 + n + i] = v[i]
    out_last[1 + 2 * n] = iters
    out_last[2 + 2 * n] = resid
    for k in range(min(extra.shape[0], out_last.shape[0] - 3 - 2 * n)):
        out_last[3 + 2 * n + k] = extra[k]


# Imported here, not at the top: events.py, hermite.py and work.py import FAST, accel and
# copy_into from this module.
from . import events, hermite, work  # noqa: E402


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
    out_stats[:, STAT_WORK] holds W, the work since t0 (steppers/core/work.py; 0 when kern.WORK is
    False), continued from out_stats[0, STAT_WORK]; an out_last one entry longer receives the
    final W in its last entry.
    out_last (2n + 3 + n_saved,) receives [t, q, v, Newton iterations since the last save,
    Newton residual, saved fields] of the final state, or on failure: of the state the failing
    step started from (Newton failure, singular mass) or of the offending state after it
    (NON_FINITE, UNSTABLE; also a non-finite energy at a saved state).
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
    allocation and no compile time (typing them cost about 2.5 s per module).
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
    if out_extra.shape[1] != n_saved or out_last.shape[0] - 2 * n - 3 - n_saved not in (0, 1):
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
    inlined paid for the count of every array it touched (rk4 170 against 100 ns per step on
    the cart pendulum), and a step called paid for the call. Cart pendulum, best of 7 runs of
    1e5 steps, one process, the module's glue before -> after: rk4 102 -> 78 ns,
    symplectic_euler 183 -> 138, verlet 276 -> 219, explicit_euler 18 -> 18; its compile (a
    fresh process, the library's own numba cache warm) about 1 s longer, an extra compiled
    layer (rk4 3.6 -> 4.8 s, verlet 11.4 -> 12.2 s, composition 14.2 -> 16.1 s). The
    portable glue (loop None in run_loop) keeps the steps inlined in run_loop and calls the
    step: as a loop of its own there, the first use of a method after an install compiled 2 s
    longer (rk4 5.7 -> 7.8 s, verlet 18.1 -> 20.1 s, fresh numba cache)."""
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
                    if out_last.shape[0] > 2 * n + 3 + n_saved:
                        out_last[out_last.shape[0] - 1] = W     # (W at the end of the step)
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
    if out_last.shape[0] > 2 * n + 3 + n_saved:
        out_last[out_last.shape[0] - 1] = W
    return OK, n_steps, n_events
