"""numba options of the per-step path, the inline model of a method's step, and the rules on
loop bounds every stepper function follows.

Speed: everything called once or more per step is compiled with jit.NO_REFCOUNT (numba's switch for
"no reference counting"; none of these functions allocates). With reference counting on, numba
increments and decrements an atomic counter for every array argument of every call and every array
view that its pruning pass cannot prove redundant, which is most of them in functions with loops and
early returns: on the cart pendulum the counting would be about half of the run time of the Newton
methods (NRT_incref/NRT_decref in a profile), and it makes a 2 x 2 LU solve through calls about
three times slower. Only ``run_loop`` allocates (once per run) and keeps reference counting; the
steps run in the stepping loop it calls (run_loop.stepping_loop), which does not.

Loop bounds: the fixed-step methods' per-step loops over the coordinates (the steps, the
Newton loops of newton.py, explicit_rk's stages, and the helpers of solve.py and legendre.py
that take an ``n``) run to ``kern.N_COORDS``, not to an array's shape. In a generated module's
glue that is a compile-time constant, so LLVM unrolls the loops of a small model into
straight-line code (the 2 x 2 cart pendulum) and knows every trip count of a larger one; in the
portable glue it is a field of the kernel table, a run-time value like the shape. run_loop
refuses a state of another length. On the cart pendulum the constant bound makes the implicit
methods' steps markedly faster, the partitioned ones most (their Newton loops unrolled), and
leaves explicit_euler and rk4 as they are (ns per step: ``lagrange-gen bench steppers``,
reports/steppers.md).
Methods whose Newton unknowns are not the coordinates (the constrained ones) pass x.shape[0].
"""

from ...jit import NO_REFCOUNT, njit

#: numba options of every function on the per-step path (see the module docstring).
#: error_model="numpy": a division by zero gives inf/NaN (caught as NON_FINITE by check_state or
#: failed_solve_status) instead of raising ZeroDivisionError from inside the jitted loop, and
#: numba drops its zero-divisor checks on every division.
FAST = dict(**NO_REFCOUNT, error_model="numpy")


def inline_step(expr, caller_ir, callee_ir):
    """numba inline cost model (``@njit(inline=inline_step)``) of every fixed-step method's
    ``step``: inlined into the loops compiled without reference counting (declared with
    fast_loop: the stepping loop of a generated module's glue, stepping_loop, and the step
    API's), called from everywhere else. Inlined into a reference-counted loop (the portable
    glue's run_loop), rk4's step on the cart pendulum takes about 1.7 times as long (every
    array the step touches is counted there)."""
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
