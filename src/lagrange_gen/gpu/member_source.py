"""Which methods and models the GPU path runs, and the source text of its member function and
kernel for one generated module and method.

The member function is run_loop.run_loop's set-up written out (run_loop allocates with numpy,
which device code cannot), then the CPU library's own ``run_loop.steps`` (every step, state check,
save and failure exactly as on the CPU), then the final row the CPU ensemble glue writes
(codegen/glue.py, _member_<method>). Its arrays are per-thread local arrays of fixed sizes:
the shapes are those the method's CPU ``workspace`` allocates for this module (its Python
original, run once here), written into the text as literals, as a CUDA local array needs.

Shapes: n coordinates, S saved rows; q0, v0 (M, n); p (M, n_params); out_q, out_v (M, S, n);
out_stats (M, S, N_STATS); out_extra (M, S, n_saved); out_last (M, last_size); out_status (M, 3)
int64 (status, steps_done, n_events); out_t (S,) one row of times shared by every member (each
thread writes the same values).
"""

from __future__ import annotations

import importlib

import numpy as np

from ..steppers.core import registry, work

#: Threads per block of a launch (one member per thread).
THREADS_PER_BLOCK = 128


def refusal(module, method) -> str:
    """Why the GPU path does not run ``method`` on this module (one line), or ""."""
    if method not in registry.GPU_METHODS:
        return (f"{module.NAME}: method {method!r} does not run on the GPU yet; device='cuda' "
                f"runs {', '.join(registry.GPU_METHODS)} (device='cpu' runs every fixed-step "
                f"method)")
    if getattr(module, "N_EVENTS", 0):
        return (f"{module.NAME}: events are not located on the GPU yet (the model has "
                f"{module.N_EVENTS}); use device='cpu'")
    return ""


def method_module(method):
    """The stepper module of ``method`` (steppers/methods/<method>.py)."""
    return importlib.import_module(f"lagrange_gen.steppers.methods.{method}")


def _local(array, float_name):
    """Text of a local array with ``array``'s shape and kind (float: float_name, int: INT). A
    size-0 dimension (a model without work or without saved fields) is allocated as 1 and sliced
    to 0: a CUDA local array needs a positive size."""
    dtype = float_name if array.dtype.kind == "f" else "INT"
    shape = tuple(int(d) for d in array.shape)
    alloc = tuple(max(d, 1) for d in shape)
    text = f"cuda.local.array({alloc if len(alloc) > 1 else alloc[0]}, {dtype})"
    if alloc != shape:
        text += "[" + ", ".join(f":{d}" for d in shape) + "]"
    return text


def _tuple_text(record, float_name):
    """``Name(cuda.local.array(...), ...)`` for a workspace record of arrays (a namedtuple)."""
    fields = []
    for value in record:
        if not isinstance(value, np.ndarray):
            raise NotImplementedError(f"workspace field of type {type(value).__name__}")
        fields.append(_local(value, float_name))
    return ",\n        ".join(fields)


def _zero_text(name, record):
    """Lines zeroing every array of a workspace record (the CPU allocates them with np.zeros;
    a local array starts with whatever the memory held)."""
    lines = []
    for field, value in zip(record._fields, record):
        loops = "".join(f"for i{d} in range({value.shape[d]}):\n{'    ' * (d + 2)}"
                        for d in range(value.ndim))
        index = ", ".join(f"i{d}" for d in range(value.ndim))
        if value.size:
            lines.append(f"    {loops}{name}.{field}[{index}] = 0")
    return "\n".join(lines)


def member_source(module, method, n_saved) -> str:
    """Source text of ``member(...)`` for this module and method (n_saved: SPEC.n_saved on
    this model); the names it reads are bound by kernels.py."""
    stepper = method_module(method)
    n = module.N_COORDS
    ws = stepper.workspace.py_func(module, n)
    ww = work.workspace.py_func(module, n)
    extra = _local(np.zeros(n_saved), "FLOAT")
    return _TEMPLATE.format(
        n=n, n_saved=n_saved, method=method, workspace=_tuple_text(ws, "FLOAT"),
        work_workspace=_tuple_text(ww, "FLOAT"), extra=extra,
        zero_ws=_zero_text("ws", ws), zero_ww=_zero_text("ww", ww))


def _setting_widths(method):
    """[(name, width)] of the method's settings record: width 0 for a scalar, k for a k-tuple
    (index1's baumgarte = (alpha, beta))."""
    defaults = method_module(method).SPEC.settings()
    return [(name, len(value) if isinstance(value, tuple) else 0)
            for name, value in zip(defaults._fields, defaults)]


def flat_settings(method, config) -> tuple:
    """The settings record ``config`` as the kernel's scalar arguments (tuples spread out): a
    kernel argument must be a scalar or an array."""
    flat = []
    for (name, width), value in zip(_setting_widths(method), config):
        flat.extend(value if width else (value,))
    return tuple(flat)


def kernel_source(method) -> str:
    """Source text of ``ensemble_kernel(...)``, which runs ``member`` for member i = the
    thread's index (the settings record passed as scalars, flat_settings, and rebuilt)."""
    args, fields = [], []
    for name, width in _setting_widths(method):
        parts = [f"s_{name}_{k}" for k in range(width)] if width else [f"s_{name}"]
        args.extend(parts)
        fields.append(f"({', '.join(parts)},)" if width else parts[0])
    return _KERNEL.format(setting_args="".join(f"{a}, " for a in args),
                          settings=", ".join(fields))


_TEMPLATE = '''
def member(q0, v0, t0, h, n_steps, save_every, p, settings, out_t, out_q, out_v, out_stats,
           out_extra, out_last, out_events):
    """One member with {method}: (status, steps_done, n_events) as run_loop.run_loop."""
    q = cuda.local.array({n}, FLOAT)
    v = cuda.local.array({n}, FLOAT)
    mom = cuda.local.array({n}, FLOAT)
    for k in range({n}):
        q[k] = q0[k]
        v[k] = v0[k]
        mom[k] = 0.0
    ws = Workspace(
        {workspace})
{zero_ws}
    ww = WorkWorkspace(
        {work_workspace})
{zero_ww}
    extra = {extra}
    for k in range({n_saved}):
        extra[k] = out_extra[0, k]
    W = out_stats[0, STAT_WORK]
    if W != W:
        W = 0.0
    bound = settings.blowup_bound
    status = check_state(q, v, bound)
    if status == OK:
        status = method.prepare(kern, q, v, mom, t0, p, settings, ws, extra)
    energy = kern.energy(q, v, t0, p)
    if status == OK and not math.isfinite(energy):
        status = NON_FINITE
    write_last(out_last, t0, q, v, 0.0, 0.0, extra)
    if status != OK:
        return status, -1, 0
    save_row(0, t0, q, v, energy, 0.0, 0.0, out_t, out_q, out_v, out_stats, extra, out_extra)
    out_stats[0, STAT_WORK] = W
    P0, D0 = 0.0, 0.0
    if kern.WORK:
        P0, D0 = work.rate(kern, ww, q, v, t0, p)
    outs = (out_t, out_q, out_v, out_stats, out_extra, out_last, out_events)
    aux = (ww, None, None, W, P0, D0, bound)
    status, done, n_events = steps(method, kern, {n_saved}, 0, q, v, mom, ws, extra, t0, h,
                                   n_steps, save_every, p, settings, outs, aux, None, None)
    if status == OK and (done % save_every != 0 or done < n_steps):
        row = done // save_every + 1
        v_at = layout.v_at({n})
        e_at = layout.extra_at({n})
        for k in range({n}):
            out_q[row, k] = out_last[layout.Q + k]
            out_v[row, k] = out_last[v_at + k]
        energy = kern.energy(out_q[row], out_v[row], out_last[layout.T], p)
        out_stats[row, layout.STAT_ENERGY] = energy
        out_stats[row, layout.STAT_ITERS] = out_last[layout.iters_at({n})]
        out_stats[row, layout.STAT_RESIDUAL] = out_last[layout.resid_at({n})]
        for k in range({n_saved}):
            out_extra[row, k] = out_last[e_at + k]
        if not math.isfinite(energy):
            status, done = NON_FINITE, done - 1
    return status, done, n_events
'''

_KERNEL = '''
def ensemble_kernel(q0, v0, t0, h, n_steps, save_every, p, {setting_args}out_t, out_q,
                    out_v, out_stats, out_extra, out_last, out_status, out_events):
    """Member i = the thread's index; members past q0.shape[0] do nothing."""
    i = cuda.grid(1)
    if i < q0.shape[0]:
        settings = Settings({settings})
        status, done, n_events = member(
            q0[i], v0[i], t0, h, n_steps, save_every, p[i], settings, out_t, out_q[i],
            out_v[i], out_stats[i], out_extra[i], out_last[i], out_events)
        out_status[i, 0] = status
        out_status[i, 1] = done
        out_status[i, 2] = n_events
'''
