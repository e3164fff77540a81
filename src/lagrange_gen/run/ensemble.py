"""Many runs of one model in one call: members differing in q0, v0 and parameters.

    import lagrange_gen as lg
    ens = lg.ensemble("models/cart_pendulum.py", "rk4", q0=q0s, params=lg.grid(k=ks, m=ms),
                      t_end=10, h=1e-3, save_every=100)
    ens.q            # (M, S, n)
    ens.failures()   # ["member 17: cart_pendulum, explicit_euler: step 312 of 1000 ..."]
    ens.to_dataframe()   # pandas: one row per member and saved state
    ens.params_by_name["k"]   # (M,); ens.plot("ens.png"); ens.save("ens.npz"); EnsembleResult.load

Without save_every, every step is saved unless that would hold more than OUTPUT_BUDGET_BYTES
(or a quarter of the memory available): then the smallest save_every that fits is chosen and
one warning line says which.

The members run in the generated module's ``ensemble_<method>`` (codegen/glue.py): one
numba parallel loop over members, each member run_loop.run_loop exactly as ``run_<method>`` runs it
for simulate, so member i equals ``simulate(...)`` with member i's inputs (bitwise, as long as
simulate runs in one chunk: fixed_run.CHUNK_STEPS steps). Fixed-step methods only. A member that
fails (blow-up, Newton failure, singular matrix) stops alone: its status, step, time and state are
kept, its rows after the failure are NaN, the other members finish.
"""

from __future__ import annotations

import math
import time
import warnings
from dataclasses import dataclass, field

import numpy as np

from . import checks as run_checks
from ..codegen.keys import regeneration_command_for
from .ensemble_inputs import grid, member_count, member_params, member_states
from .ensemble_outputs import (allocate_outputs, dataframe, member_args, read_ensemble,
                               run_members, write_ensemble)
from ..errors import LagrangeGenError, SimulationError
from .failures import raise_for_status
from .fixed_driver import ProgressBar, n_steps_to
from ..jit.compile_notice import first_use_notice
from ..jit.portable import choose_ensemble, jit_mode
from .memory import available_memory
from ..steppers.core import status as st
from ..steppers.core import registry
from ..steppers.core.layout import (N_STATS, STAT_ENERGY, STAT_ITERS, STAT_RESIDUAL, T,
                                    state_slice)
from ..steppers.core.method_spec import make_settings

__all__ = ["ensemble", "grid", "EnsembleResult"]

#: With a progress bar, members run in batches of at least this many per thread (a batch ends
#: when its slowest member does, so batches of one member per thread would idle threads).
MEMBERS_PER_THREAD = 32

#: Without save_every, the saved output (ensemble_bytes) is kept under this many bytes, and under
#: a quarter of the memory available.
OUTPUT_BUDGET_BYTES = 256 * 2**20


@dataclass
class EnsembleResult:
    """Outputs of an ensemble of M members, S saved rows, n coordinates.

    t (S,); q, v (M, S, n); energy, newton_iters, newton_residual (M, S); saved {field: (M, S, w)}
    (the method's SPEC.saved); status (M,) lagrange_gen.steppers.core.status codes (0 = OK); steps_done (M,)
    (steps completed, also for a failed member); fail_time (M,) and fail_state (M, 2 n) (time and
    [q, v] where the member stopped: the final state when it succeeded); params (M, n_params) in
    param_names order. Rows after a member's failure are NaN."""

    t: np.ndarray
    q: np.ndarray
    v: np.ndarray
    energy: np.ndarray
    newton_iters: np.ndarray
    newton_residual: np.ndarray
    saved: dict
    status: np.ndarray
    steps_done: np.ndarray
    fail_time: np.ndarray
    fail_state: np.ndarray
    params: np.ndarray
    param_names: tuple
    coords: tuple
    model: str
    method: str
    h: float
    n_steps: int
    wall_time: float
    compile_time: float
    messages: dict = field(default_factory=dict)    # {member: one-line failure message}
    jit: str = ""       # the glue that ran: "specialized" or "portable" (ensemble(jit=))
    device: str = "cpu"     # where the members ran: "cpu", or the GPU's name (device="cuda")

    @property
    def ok(self):
        """(M,) bool: the members that reached t_end (or a terminal event)."""
        return self.status == st.OK

    def failures(self):
        """["member i: <the message simulate would raise>", ...] for the failed members."""
        return [f"member {i}: {self.messages[i]}" for i in sorted(self.messages)]

    @property
    def params_by_name(self) -> dict:
        """{parameter name: (M,) its value per member}, in param_names order (views of
        ``params``)."""
        return {name: self.params[:, j] for j, name in enumerate(self.param_names)}

    def to_dataframe(self):
        """A long (tidy) pandas.DataFrame, one row per member and saved state (M S rows):
        member, the parameters (param_names), t, the coordinates, their velocities (name_dot)
        and energy. pandas is the optional extra ``lagrange-gen[dataframe]``."""
        return dataframe(self)

    def save(self, path):
        """Write every field to a .npz file (the layout of Trajectory.save);
        EnsembleResult.load reads it back."""
        write_ensemble(self, path)

    @classmethod
    def load(cls, path) -> "EnsembleResult":
        """The EnsembleResult written by save; one LagrangeGenError line for a file that is not
        one (a Trajectory's file included)."""
        return read_ensemble(cls, path)

    def plot(self, path=None, members=None):
        """Every member's coordinates and velocities (one axis each, one line per member,
        labelled by its parameters when few) and energy error E - E0 (viz/plot.py
        plot_ensemble). ``members``: the indices to draw (default all, at most
        viz.plot.MAX_MEMBERS evenly chosen). Writes ``path`` (.png, .pdf, .svg) or returns the
        Figure."""
        from ..viz.plot import plot_ensemble
        return plot_ensemble(self, path, members)


def ensemble(module_or_path, method="midpoint", *, q0=None, v0=None, params=None, t_end=None,
             h=None, save_every=None, t0=0.0, progress=False, out_dir=None, client=None,
             worker_threads=1, jit=None, device="cpu", dtype="float64", **settings):
    """Integrate M members of one model with a fixed-step method; an EnsembleResult.

    t_end and the step h are required (each missing one is a SimulationError line naming it).

    q0, v0: (n,) shared or (M, n) per member (default zeros); params: dict {name: value or (M,)
    array} (see grid), or an (M, n_params) table in PARAMS order; settings: the method's settings
    by name (as simulate), shared. M comes from the per-member inputs, which must agree.
    save_every: keep every save_every-th step; None: every step unless the output would exceed
    OUTPUT_BUDGET_BYTES (or a quarter of the available memory), then the smallest save_every
    that fits, with a warning saying so (default_save_every).
    Constrained models: each member's (q0, v0) is made consistent first (lagrange_gen.run.consistent;
    one warning counts the members moved). out_dir: where a model file is generated (default
    codegen.keys.default_generated_dir: the same place from any working directory). Raises
    SimulationError (one line) on bad input or when the saved output would not fit in memory;
    failing members do not raise (failures()).
    client: a dask.distributed Client: the members run as Dask tasks in chunks on its workers,
    each on ``worker_threads`` numba threads (run/ensemble_dask.py); the result is the same.
    jit: as simulate's (lagrange_gen.jit.portable): "auto" runs the generated ensemble_<method> when
    numba's cache holds it, else the portable ensemble glue, compiled once for every model
    (models with events: always the generated one); the Dask path runs the generated one.
    EnsembleResult.jit says which ran.
    device: "cpu", or "cuda": one GPU thread per member (lagrange_gen.gpu; needs numba-cuda, the
    ``gpu`` extra), the same EnsembleResult; the methods registry.GPU_METHODS, models without
    events; dtype "float64" or "float32" (GPU only: state, parameters and outputs in float32,
    returned as float64 arrays); no progress bar. Anything the GPU path cannot run, and a
    missing numba-cuda, driver or GPU, is one SimulationError line."""
    from .simulate import check_required, check_times, element_method, load_module
    check_required("ensemble", t_end=t_end, h=h)
    if method not in registry.METHODS:
        raise SimulationError(registry.unknown_method(method))
    jit = jit_mode(jit)
    module = load_module(module_or_path, out_dir, method)
    method = element_method(module, method)
    from .consistent import check_method
    check_method(module, method)
    spec = registry.spec(method)
    if spec.adaptive:
        raise SimulationError(f"method {method!r} chooses its own steps; ensemble runs the "
                              f"fixed-step methods only (e.g. rk4, midpoint, verlet)")
    on_gpu = _check_device(device, dtype, client)
    run = None if on_gpu else _ensemble_glue(module, method)
    if client is not None:
        from .ensemble_dask import check_client
        check_client(client)
    h = check_times(spec, h, t0, t_end, 1 if save_every is None else save_every, None)
    config = make_settings(spec, settings)
    if on_gpu:
        from ..gpu.launch import check_gpu_request
        check_gpu_request(module, method, dtype, config)
    M = member_count(module, q0, v0, params)
    if M < 1:
        raise SimulationError(f"{module.NAME}: an ensemble of 0 members: the per-member inputs "
                              f"(q0, v0 (M, n), params arrays (M,)) are empty")
    t0, t_end = float(t0), float(t_end)
    n_steps = n_steps_to(t0, t_end, h)
    run_checks.check_time_resolution(t0, t0 + n_steps * h, h, n_steps)
    n, n_saved = module.N_COORDS, spec.n_saved(module.N_COORDS, module.N_CONSTRAINTS,
                                               module.N_ELEMENTS, getattr(module, "N_CONTACTS", 0),
                                               getattr(module, "N_NONHOLONOMIC", 0))
    if save_every is None:
        save_every = default_save_every(module.NAME, M, n_steps, n, n_saved, module.N_PARAMS)
    save_every = int(save_every)
    rows = run_checks.saved_rows(n_steps, save_every)
    # Before the member tables: for 1e9 members q0 alone is 16 GB.
    check_ensemble_memory(module.NAME, M, n_steps, save_every, n, n_saved, module.N_PARAMS)
    q, v = member_states(module, "q0", q0, M), member_states(module, "v0", v0, M)
    p = member_params(module, params, M)
    for i in range(M) if getattr(module, "N_ELEMENTS", 0) else ():
        run_checks.check_element_coefficients(module, p[i])
    for i in range(M) if getattr(module, "N_CONTACTS", 0) else ():
        run_checks.check_contact_coefficients(module, p[i], q[i])
    out = allocate_outputs(M, rows, n, n_saved)
    if spec.saves_constraints(module.N_CONSTRAINTS):
        q, v = _consistent_starts(module, q, v, p, t0, config, out["extra"])
    if on_gpu:
        from ..gpu.launch import run_on_gpu
        compile_time, wall, where = run_on_gpu(module, method, q, v, p, t0, h, n_steps,
                                               save_every, config, out, dtype)
        result = _result(module, spec, out, p, t0, h, n_steps, save_every, wall, compile_time,
                         getattr(config, "max_iter", 0))
        result.jit, result.device = f"cuda {dtype}", where
        return result
    if client is None:
        run, ran, compile_time = _warm_up(
            lambda args: choose_ensemble(jit, run, module, method, args),
            f"ensemble_{method} for {module.NAME}", q, v, p, t0, h, save_every, config, out)
    else:
        ran, compile_time = "specialized", 0.0   # done by each worker, inside its first task
    start = time.perf_counter()
    if client is None:
        _run_batches(run, q, v, p, t0, h, n_steps, save_every, config, out, progress)
    else:
        from .ensemble_dask import run_on_client
        run_on_client(client, module, method, q, v, p, t0, h, n_steps, save_every, config, out,
                      progress, worker_threads)
    wall = time.perf_counter() - start
    result = _result(module, spec, out, p, t0, h, n_steps, save_every, wall, compile_time,
                     getattr(config, "max_iter", 0))
    result.jit = ran
    return result


def _check_device(device, dtype, client):
    """True for device="cuda"; one-line SimulationError for what does not go together."""
    if device not in ("cpu", "cuda"):
        raise SimulationError(f"device {device!r}: expected 'cpu' or 'cuda'")
    if device == "cpu" and dtype != "float64":
        raise SimulationError(f"dtype {dtype!r} runs on device='cuda' only; the CPU ensemble "
                              f"is float64")
    if device == "cuda" and client is not None:
        raise SimulationError("device='cuda' runs on this machine's GPU: pass no Dask client")
    return device == "cuda"


def _ensemble_glue(module, method):
    run = getattr(module, f"ensemble_{method}", None)
    if run is None:
        raise SimulationError(
            f"{module.NAME}: module {module.__file__} has no ensemble glue for {method!r} "
            f"(generated before ensembles, or without that method); run "
            f"`{regeneration_command_for(module, methods=[method])}`")
    return run


def ensemble_bytes(M, rows, n, n_saved, n_params=0):
    """Bytes an ensemble holds at its peak: per member and row q, v, stats, extra, and the
    energy / Newton copies of the result; per member its q0, v0 and parameters."""
    return M * rows * 8 * (2 * n + N_STATS + n_saved + 3) + M * 8 * (2 * n + n_params)


def default_save_every(model, M, n_steps, n, n_saved, n_params=0):
    """The smallest save_every whose output (ensemble_bytes) fits the budget: OUTPUT_BUDGET_BYTES
    or a quarter of the available memory, the smaller. 1 when every step fits; otherwise a
    UserWarning line says what was chosen and how to choose."""
    free = available_memory()
    budget = OUTPUT_BUDGET_BYTES if free is None else min(OUTPUT_BUDGET_BYTES, free // 4)

    def size(k):
        return ensemble_bytes(M, run_checks.saved_rows(n_steps, k), n, n_saved, n_params)
    if size(1) <= budget:
        return 1
    per_row = size(1) - size(n_steps) if n_steps > 1 else size(1)
    per_row = max(per_row // max(n_steps - 1, 1), 1)
    k = max(1, math.ceil(n_steps / max((budget - size(n_steps)) // per_row, 1)))
    while k > 1 and size(k - 1) <= budget:
        k -= 1
    while k < n_steps and size(k) > budget:
        k += 1
    rows = run_checks.saved_rows(n_steps, k)
    warnings.warn(f"{model}: an ensemble of {M} members saving every step would hold "
                  f"{_size(size(1))}; saving one step in {k} instead: save_every={k} ({rows} "
                  f"states of {n_steps + 1}, {_size(size(k))}); pass save_every= (--save-every) "
                  f"to choose", UserWarning, stacklevel=3)
    return k


def _size(nbytes):
    """'2.69 GB', '250 MB', '19.5 kB' (binary units)."""
    for unit, scale in (("GB", 2**30), ("MB", 2**20)):
        if nbytes >= scale:
            return f"{nbytes / scale:.3g} {unit}"
    return f"{nbytes / 2**10:.3g} kB"


def check_ensemble_memory(model, M, n_steps, save_every, n, n_saved, n_params=0):
    """Refuse, before allocating, an ensemble whose saved rows do not fit in the memory available
    now (run_checks.check_memory with the ensemble's bytes), saying how much it needs and which
    save_every fits."""
    rows = run_checks.saved_rows(n_steps, save_every)
    run_checks.check_memory(model, n_steps, save_every, n, n_saved,
                            need=ensemble_bytes(M, rows, n, n_saved, n_params),
                            what=f"an ensemble of {M} members saving {rows} states each")


def _consistent_starts(module, q, v, p, t0, config, extra):
    """Each member's consistent (q0, v0), its multipliers and residuals in row 0 of ``extra``
    (its last entries: a contact method saves its contact fields before them); one warning
    counting the members that were moved (instead of one per member)."""
    from .consistent import consistent_initial_state
    tol = getattr(config, "newton_tol", 1e-12)
    q, v, moved = q.copy(), v.copy(), 0
    for i in range(q.shape[0]):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            state = consistent_initial_state(module, q[i], v[i], p[i], t0, tol)
        moved += bool(caught)
        q[i], v[i] = state.q, state.v
        start = np.concatenate((state.lam, [state.phi_norm, state.jv_norm]))
        extra[i, 0, extra.shape[2] - start.shape[0]:] = start
    if moved:
        warnings.warn(f"{module.NAME}: the initial state of {moved} of {q.shape[0]} members was "
                      f"projected onto the constraints (lagrange_gen.run.consistent)", stacklevel=3)
    return q, v


def _warm_up(choose, label, q, v, p, t0, h, save_every, config, out):
    """Choose the glue (``choose(args)`` -> (glue, what ran), portable.choose_ensemble) and
    compile or load it from numba's cache with zero members, with the compile notice naming
    ``label`` when that takes long; (glue, what ran, seconds)."""
    start = time.perf_counter()
    args = member_args(q, v, p, t0, h, 0, save_every, config, out, slice(0, 0))
    with first_use_notice(label):
        run, ran = choose(args)
        run(*args)
    return run, ran, time.perf_counter() - start


def _run_batches(run, q, v, p, t0, h, n_steps, save_every, config, out, progress):
    """One call for all members, or with a progress bar batches of about 2 % of them (at least
    MEMBERS_PER_THREAD per thread)."""
    M = q.shape[0]
    if not progress:
        run_members(run, q, v, p, t0, h, n_steps, save_every, config, out, slice(0, M))
        return
    from ..jit.api import get_num_threads
    batch = max(MEMBERS_PER_THREAD * get_num_threads(), math.ceil(M / 50))
    bar = ProgressBar(M)
    for start in range(0, M, batch):
        members = slice(start, min(M, start + batch))
        run_members(run, q, v, p, t0, h, n_steps, save_every, config, out, members)
        bar.update(members.stop)
    bar.close()


def _result(module, spec, out, p, t0, h, n_steps, save_every, wall, compile_time, max_iter):
    n, rows = module.N_COORDS, out["q"].shape[1]
    t = t0 + h * save_every * np.arange(rows, dtype=np.float64)
    t[-1] = t0 + h * n_steps if n_steps % save_every else t[-1]
    status, steps = out["status"][:, 0].copy(), out["status"][:, 1].copy()
    last = out["last"]
    layout = spec.saved_layout(n, module.N_CONSTRAINTS, module.N_ELEMENTS,
                               getattr(module, "N_CONTACTS", 0),
                               getattr(module, "N_NONHOLONOMIC", 0))
    saved = {name: out["extra"][:, :, a:a + w] for name, a, w in layout}
    energy = out["stats"][:, :, STAT_ENERGY].copy()
    if "element_state" in saved:
        from .run_result import element_energy
        for i in range(p.shape[0]):
            energy[i] += element_energy(module, p[i], saved["element_state"][i])
    messages = {int(i): _message(module, spec, int(status[i]), int(steps[i]), n_steps, last[i],
                                 h, p[i], max_iter) for i in np.flatnonzero(status != st.OK)}
    done = np.where(status == st.OK, steps, np.maximum(steps, 0))
    return EnsembleResult(
        t=t, q=out["q"], v=out["v"], energy=energy,
        newton_iters=out["stats"][:, :, STAT_ITERS].copy(),
        newton_residual=out["stats"][:, :, STAT_RESIDUAL].copy(), saved=saved, status=status,
        steps_done=done, fail_time=last[:, T].copy(), fail_state=last[:, state_slice(n)].copy(),
        params=p, param_names=tuple(module.PARAMS), coords=tuple(module.COORDS),
        model=module.NAME, method=spec.name, h=h, n_steps=n_steps, wall_time=wall,
        compile_time=compile_time, messages=messages)


def _message(module, spec, code, steps, n_steps, last, h, p, max_iter):
    """The one line simulate would raise for this member (failures.raise_for_status)."""
    try:
        raise_for_status(code, module, spec.name, steps + 1, n_steps, last, max_iter, h, p)
    except LagrangeGenError as exc:
        return str(exc).splitlines()[0]
    return f"status {code}"
