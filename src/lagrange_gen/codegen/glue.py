"""The stepper glue of a generated module's methods, and the portable glue.

Why glue: numba caches a compiled function on disk only when it takes no function arguments.
The cores in ``steppers/methods/<method>.py`` are generic over the kernels: they receive the generated
module itself as their first argument (``kern``; see steppers/core/run_loop.py for why a module and not the
dispatchers), so they cannot be cached on their own. The specialized glue ``run_<method>``
passes one generated module and takes only arrays and scalars, so it is ``cache=True`` and its
compiled code, cores and kernels included, is loaded from numba's cache by the next process.

A generated module holds kernels and metadata only: the library writes its specialized glue
(specialized_glue_source) into its own cache folder on first use (jit/specialized.py), under a
file name that carries the module's KEY and the library version, so that a changed model or a
changed stepper compiles again and nothing else does.

Glue signature of the fixed-step methods::

    run_<method>(q0, v0, t0, h, n_steps, save_every, p, settings,
                 out_t, out_q, out_v, out_stats, out_extra, out_last) -> (status, steps_done)

    q0, v0     (n,) float64      initial state at time t0
    h          float             step (may be negative: steps backwards in time)
    n_steps, save_every  int     saves after every save_every-th step, plus row 0
    p          (n_params,)       parameter values in PARAMS order
    settings   the method's settings record (SPEC.settings, built by spec.make_settings)
    out_t (S,), out_q (S, n), out_v (S, n), out_stats (S, N_STATS), out_extra (S, n_saved)
               S = n_steps // save_every + 1; n_saved = SPEC.n_saved(n, m, ne), the method's
               saved fields (multipliers and residuals, element states; none for most)
    out_last   (2 n + 3 + n_saved,)  [t, q, v, Newton iterations since the last save, Newton
                                 residual, saved fields] at the end, or at the failure
               (steppers/core/layout.py)
    status     lagrange_gen.steppers.core.status code; steps_done = index of the failing step on failure, -1
               when the initial state is refused (see run_loop.run_loop)

Fixed-step methods also get ``ensemble_<method>(q0, v0, t0, h, n_steps, save_every, p, settings,
out_q, out_v, out_stats, out_extra, out_last, out_status)``: the same loop for M members at once
(a numba prange over members; member arrays with a leading M axis, see _ENSEMBLE_GLUE and
lagrange_gen.ensemble).

The glue is compiled with error_model="numpy", like the kernels and the cores: non-finite
arithmetic gives inf/NaN, which the run loop reports as NON_FINITE, never a Python exception.
"""

from __future__ import annotations

from ..steppers.core.registry import LOOPS, spec


#: Glue arguments of the adaptive methods (see adaptive.run_adaptive).
ADAPTIVE_GLUE_ARGS = ("q0, v0, t0, t_end, p, settings, t_eval, "
                      "out_t, out_q, out_v, out_stats, out_extra, out_last, out_events, counters")

GLUE_ARGS = ("q0, v0, t0, h, n_steps, save_every, p, settings, "
             "out_t, out_q, out_v, out_stats, out_extra, out_last, out_events")


# _THIS_MODULE (the generated module, typed by numba as a compile-time constant) is what the
# cores call kernels through; the glue file names it by the name it was imported under, which
# numba's cache refers to it by.
_GLUE = '''"""Stepper glue of {method} for the generated module {module_name!r} (KEY {key}),
written by lagrange_gen.jit.specialized; DO NOT EDIT.

Library version {digest} (a hash of the package files it compiles)."""
import sys as _sys

import numpy as np

from lagrange_gen.jit import njit
from lagrange_gen.steppers.methods import {method} as _stepper_{method}
from lagrange_gen.steppers.core.{loop_module} import {loop} as _{loop}{loop_import}

_THIS_MODULE = _sys.modules[{module_name!r}]{loop_def}


@njit(cache=True, error_model="numpy")
def run_{method}({wrapped}):
    """Integrate with {method} ({summary}); returns (status, steps_done, n_events).

    Argument shapes: see lagrange_gen.codegen.glue; lagrange_gen.simulate wraps this."""
    return _{loop}(_stepper_{method}, {loop_arg}_THIS_MODULE, {n_saved}, {n_events}, {wrapped_call})'''

# The portable glue (lagrange_gen.jit.portable): the same loop and method module, with the kernels
# and constants of any model passed in as ``kern``, a named tuple of first-class functions whose
# numba type is the same for every model, so that the method compiles once for all models.
_PORTABLE_GLUE = '''"""Portable glue of {method}, written by lagrange_gen.jit.portable; DO NOT EDIT.

Library version {digest} (a hash of the package files it compiles)."""
import numpy as np

from lagrange_gen.jit import njit
from lagrange_gen.steppers.methods import {method} as _stepper_{method}
from lagrange_gen.steppers.core.{loop_module} import {loop} as _{loop}{loop_import}{loop_def}


@njit(cache=True, error_model="numpy")
def run_{method}(kern, n_saved, {wrapped}):
    """run_{method} of a generated module, on the kernel table ``kern`` (portable.kernel_table)
    of any model without events; n_saved: the method's saved fields on that model
    (SPEC.n_saved). The literal 0 prunes the event code before numba types it."""
    return _{loop}(_stepper_{method}, {loop_arg}kern, n_saved, 0, {wrapped_call})


@njit(cache=True, error_model="numpy")
def run_{method}_events(kern, n_saved, {wrapped}):
    """run_{method} on the kernel table of a model with events (kern.N_EVENTS > 0)."""
    return _{loop}(_stepper_{method}, {loop_arg}kern, n_saved, {events}, {wrapped_call})
'''


# The portable controlled glue (fixed-step methods): the portable glue with an input hook
# (run/control.py), a first-class function of one signature for every controller and Signal,
# so that it too compiles once per method for every model and every hook.
_CONTROLLED_GLUE = '''

@njit(cache=True, error_model="numpy")
def run_{method}_controlled(kern, n_saved, {wrapped}):
    """run_{method} with the input hook ``control(control_data, t, q, v, p) -> changed`` (a
    first-class function, portable.hook_pointer) writing the model's inputs at t0 and before
    each step; control_data: the hook's float64 vector (run/control.py)."""
    return _{loop}(_stepper_{method}, None, kern, n_saved, 0, {wrapped_call})


@njit(cache=True, error_model="numpy")
def run_{method}_controlled_events(kern, n_saved, {wrapped}):
    """run_{method}_controlled on the kernel table of a model with events."""
    return _{loop}(_stepper_{method}, None, kern, n_saved, 1, {wrapped_call})
'''

# The step API (run/stepper.py) of a fixed-step method: its state (steppers/core/step_api.py,
# a structref holding the kernel table) made, prepared and stepped by functions compiled once
# per method for every model and kept in numba's cache, as the glue above.
_STEPPER_GLUE = '''

@njit(cache=True, error_model="numpy")
def stepper_workspace_{method}(kern, n):
    """{method}'s workspace for n coordinates on the kernel table ``kern``."""
    return _make_workspace(_stepper_{method}, kern, n)


@njit(cache=True, error_model="numpy")
def stepper_new_{method}(kern, q, v, p, clock, info, settings, ws, first):
    """The StepperState of {method} on the kernel table ``kern``: q, v (n,), p (n_params,),
    clock [t0, 0, t0, h], info (2,) and the workspace ws, shared with the caller."""
    return _new_stepper_state(kern, q, v, p, clock, info, settings, ws, first)


@njit(cache=True, error_model="numpy")
def stepper_prepare_{method}(state):
    """{method}'s prepare on a StepperState: its status."""
    return _prepare_state(_stepper_{method}, state)


@njit(cache=True, error_model="numpy")
def stepper_step_{method}(state, u, k):
    """k steps of {method} with the inputs held at u (n_inputs,; empty: unchanged)."""
    return _step_state(_stepper_{method}, state, u, k)
'''

_STEPPER_IMPORT = ("\nfrom lagrange_gen.steppers.core.step_api import (\n"
                   "    make_workspace as _make_workspace, new_stepper_state as _new_stepper_state,\n"
                   "    prepare_state as _prepare_state, step_state as _step_state)\n")


#: The arguments the portable controlled glue takes after the glue's (GLUE_ARGS).
CONTROL_ARGS = ", control, control_data"


#: Arguments of the ensemble glue of a fixed-step method (lagrange_gen.ensemble wraps it).
ENSEMBLE_GLUE_ARGS = ("q0, v0, t0, h, n_steps, save_every, p, settings, "
                      "out_q, out_v, out_stats, out_extra, out_last, out_status")

# ensemble_<method> runs member i in _member_<method>: run_loop.run_loop as run_<method> runs it, on
# the member's rows of the (M, S, ...) outputs. The member is a separate (cached) function
# because numba parallelizes a prange loop only when its body has one exit, and run_loop, once
# inlined, has several (early returns, a raise). S = saved_rows: the final state gets a row when
# n_steps is not a multiple of save_every or a terminal event stopped the member, written as
# run_result.fixed_step_trajectory writes it, so a member equals simulate's Trajectory. Time
# rows and events are per-member scratch (the times are the same for every member; events are
# counted).
_ENSEMBLE_GLUE = '''import math as _math

from lagrange_gen.jit.api import prange as _prange

from lagrange_gen.steppers.core import layout as _layout
from lagrange_gen.steppers.core.status import NON_FINITE as _NON_FINITE


@njit(cache=True, error_model="numpy")
def _member_{method}({member_args}):
    """One member of ensemble_{method}: (status, steps_done, n_events) as run_{method}."""
    n = q0.shape[0]
    saves = n_steps // save_every + 1
    out_t = np.empty(saves)
    events = np.empty((0, _layout.event_width(n)))
    status, steps, n_events = _run_loop(
        _stepper_{method}, {loop}{kern}, {n_saved}, {n_events}, q0, v0, t0, h, n_steps,
        save_every, p, settings, out_t, q[:saves], v[:saves], stats[:saves], extra[:saves],
        last, events)
    if status == 0 and (steps % save_every != 0 or steps < n_steps):
        row = steps // save_every + 1
        v_at, e_at = _layout.v_at(n), _layout.extra_at(n)
        for k in range(n):
            q[row, k] = last[_layout.Q + k]
            v[row, k] = last[v_at + k]
        energy = {kern}.energy(q[row], v[row], last[_layout.T], p)
        stats[row, _layout.STAT_ENERGY] = energy
        stats[row, _layout.STAT_ITERS] = last[_layout.iters_at(n)]
        stats[row, _layout.STAT_RESIDUAL] = last[_layout.resid_at(n)]
        for k in range(extra.shape[1]):
            extra[row, k] = last[e_at + k]
        if not _math.isfinite(energy):
            status, steps = _NON_FINITE, steps - 1
    return status, steps, n_events


@njit(cache=True, parallel=True, error_model="numpy")
def ensemble_{method}({table}{wrapped}):
    """Integrate members i = 0..M-1 with {method} in one parallel loop; nothing returned.

    q0, v0 (M, n); p (M, n_params); out_q, out_v (M, S, n); out_stats (M, S, N_STATS);
    out_extra (M, S, n_saved) (row 0: the initial saved fields); out_last (M, 2 n + 3 +
    n_saved); out_status (M, 3) int64 receives (status, steps_done, n_events) per member.
    See lagrange_gen.codegen.glue; lagrange_gen.ensemble wraps this."""{unpack}
    for i in _prange(q0.shape[0]):{rebuild}
        status, steps, n_events = _member_{method}(
            {table}q0[i], v0[i], t0, h, n_steps, save_every, p[i], {settings}, out_q[i], out_v[i],
            out_stats[i], out_extra[i], out_last[i])
        out_status[i, 0] = status
        out_status[i, 1] = steps
        out_status[i, 2] = n_events'''


def glue_args(method: str) -> str:
    """The argument list of ``run_<method>`` (fixed-step or adaptive)."""
    return ADAPTIVE_GLUE_ARGS if spec(method).adaptive else GLUE_ARGS


def specialized_glue_source(method: str, module_name: str, key: str, digest: str,
                            n_saved: int, n_events: int) -> str:
    """Source text of the glue file of ``method`` for the generated module imported as
    ``module_name`` (sys.modules), whose KEY is ``key`` and whose model gives the method n_saved
    saved fields (SPEC.n_saved) and has n_events event functions, for the library version
    ``digest``: ``run_<method>``, then (fixed-step methods) ``ensemble_<method>``;
    deterministic. n_saved and n_events are passed to the loop as literals: numba prunes the
    event branches of a model without events before compiling them (a module constant would
    only be folded later, by LLVM)."""
    loop_module, loop = LOOPS[spec(method).adaptive]
    args = glue_args(method)
    wrapped = _wrap(args, f"def run_{method}(")
    wrapped_call = _wrap(args, f"    return _{loop}(")
    text = _GLUE.format(method=method, wrapped=wrapped, wrapped_call=wrapped_call,
                        summary=spec(method).summary, loop_module=loop_module, loop=loop,
                        n_saved=n_saved, n_events=n_events, module_name=module_name, key=key,
                        digest=digest, **_stepping_loop_text(method, "_THIS_MODULE", n_events))
    if not spec(method).adaptive:
        text += "\n\n" + _ensemble_source(method, n_saved, n_events, "_THIS_MODULE", "")
    return text + "\n"


def _stepping_loop_text(method, kern, n_events):
    """The parts of a glue block that bind a fixed-step method's stepping loop
    (run_loop.stepping_loop) to the generated module (kern "_THIS_MODULE") and its n_events event
    functions and pass it to run_loop; the portable glue (kern None) passes None (run_loop
    runs the steps itself), an adaptive method nothing (its loop is adaptive.run_adaptive)."""
    if spec(method).adaptive:
        return dict(loop_import="", loop_def="", loop_arg="", events="kern.N_EVENTS")
    if not kern:
        # run_loop reads only n_event_fns > 0; a literal 1 (not kern.N_EVENTS, a run-time
        # value here) lets numba prune in run_<method>_events too the branch without event
        # workspaces (ew, iw None), which it could not type
        return dict(loop_import="", loop_def="", loop_arg="None, ", events="1")
    return dict(
        loop_import="\nfrom lagrange_gen.steppers.core.run_loop import stepping_loop as _stepping_loop",
        loop_arg=f"_loop_{method}, ",
        loop_def=(f"\n\n# run_loop's steps, {method}'s step inlined (run_loop.stepping_loop)"
                  f"\n_loop_{method} = _stepping_loop(_stepper_{method}, {kern}, {n_events})"))


def portable_glue_source(method: str, digest: str) -> str:
    """Source text of the portable ``run_<method>(kern, n_saved, ...)``,
    ``run_<method>_events`` and, for a fixed-step method, ``run_<method>_controlled(kern,
    n_saved, ..., control, control_data)`` and its ``_events`` twin (_CONTROLLED_GLUE), the
    step API's ``stepper_workspace_<method>``, ``stepper_new_<method>``,
    ``stepper_prepare_<method>`` and ``stepper_step_<method>`` (_STEPPER_GLUE) and ``ensemble_<method>(kern, n_saved, ...)``
    (models without events)
    (lagrange_gen.jit.portable) for the library version ``digest``; deterministic."""
    loop_module, loop = LOOPS[spec(method).adaptive]
    args = glue_args(method)
    wrapped = _wrap(args, f"def run_{method}_events(")
    wrapped_call = _wrap(args, f"    return _{loop}(")
    source = _PORTABLE_GLUE.format(method=method, digest=digest, loop_module=loop_module,
                                   loop=loop, wrapped=wrapped, wrapped_call=wrapped_call,
                                   **_stepping_loop_text(method, None, None))
    if spec(method).adaptive:
        return source
    # ensemble_<method>(kern, n_saved, ...) for models without events (the literal 0)
    return (source + _controlled_source(method) + _STEPPER_IMPORT + _STEPPER_GLUE.format(method=method)
            + "\n\n" + _ensemble_source(method, "n_saved", 0, "kern", "kern, n_saved, "))


def _controlled_source(method):
    """_CONTROLLED_GLUE of the fixed-step ``method``."""
    args = GLUE_ARGS + CONTROL_ARGS
    return _CONTROLLED_GLUE.format(
        method=method, loop=LOOPS[False][1],
        wrapped=_wrap(args, f"def run_{method}_controlled_events("),
        wrapped_call=_wrap(args, f"    return _{LOOPS[False][1]}("))


def _ensemble_source(method, n_saved, n_events, kern, table):
    """_ENSEMBLE_GLUE for a generated module (kern "_THIS_MODULE", no table argument) or the
    portable glue (kern "kern", table "kern, n_saved, ": the kernel table passed in)."""
    wrapped = _wrap(ENSEMBLE_GLUE_ARGS, f"def ensemble_{method}(")
    member_args = table + _wrap(_MEMBER_ARGS, f"def _member_{method}(") if table else _MEMBER_ARGS
    loop = "None, " if table else f"_loop_{method}, "      # (portable: run_loop runs the steps)
    unpack, rebuild, settings = _settings_in_prange(method)
    return _ENSEMBLE_GLUE.format(method=method, wrapped=wrapped, n_saved=n_saved,
                                 n_events=n_events, kern=kern, table=table,
                                 member_args=member_args, loop=loop, unpack=unpack,
                                 rebuild=rebuild, settings=settings)


def _settings_in_prange(method):
    """(lines before the prange loop, a line opening its body, the settings name the body
    passes): ``settings`` itself, or, for a settings record with a tuple field (index1's
    baumgarte), the record rebuilt in the body from scalars read before the loop: numba's
    parallel loop cannot take a homogeneous tuple as an argument of the function it makes of
    the body."""
    record = spec(method).settings
    defaults = record()
    if not any(isinstance(value, tuple) for value in defaults):
        return "", "", "settings"
    lines, fields = [], []
    for name, value in zip(record._fields, defaults):
        if isinstance(value, tuple):
            parts = [f"_s_{name}_{k}" for k in range(len(value))]
            lines += [f"{part} = settings.{name}[{k}]" for k, part in enumerate(parts)]
            fields.append(f"({', '.join(parts)},)")
        else:
            lines.append(f"_s_{name} = settings.{name}")
            fields.append(f"_s_{name}")
    unpack = "".join(f"\n    {line}" for line in lines)
    rebuild = (f"\n        member_settings = _stepper_{method}.{record.__name__}(\n"
               f"            {', '.join(fields)})")
    return unpack, rebuild, "member_settings"


_MEMBER_ARGS = "q0, v0, t0, h, n_steps, save_every, p, settings, q, v, stats, extra, last"


def _wrap(args, opening):
    """The argument list ``args`` broken after "settings, " and aligned under ``opening``
    (the text before the first argument: "def run_verlet(", "    return _run_loop(")."""
    return args.replace("settings, ", "settings,\n" + " " * len(opening))
