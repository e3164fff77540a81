"""Ensembles beyond one machine: lagrange_gen.ensemble(..., client=dask_client).

The driver (run/ensemble.py) checks the inputs and makes constrained starts consistent as for a
local run; here the members are split into chunks, each chunk one Dask task that runs the
generated module's ``ensemble_<method>`` on its members, and the chunks' outputs are gathered
into the same arrays a local run fills. A worker imports the generated module by its path when
that file is visible to it with the same text (a shared file system; numba's cache next to it is
shared too), else it writes the source text shipped with the task to a local directory named by
the module's KEY and imports that. Nothing is derived again on a worker.

Each task runs its chunk on ``worker_threads`` numba threads (default 1: one Dask worker process
per core, as LocalCluster(threads_per_worker=1) and dask-jobqueue set them up).
"""

from __future__ import annotations

import math
import tempfile
from pathlib import Path

from ..errors import SimulationError

#: Target seconds of work per task (Dask's overhead per task is about a millisecond) and the
#: step cost used to size chunks before anything is measured (rk4 on the cart pendulum: ~2e-7 s).
CHUNK_SECONDS = 0.5
STEP_SECONDS = 3e-7

_MODULES = {}       # per worker process: (path, KEY) -> imported module


def chunk_size(M, n_steps, n_threads):
    """Members per task: about CHUNK_SECONDS of work, but at least two tasks per Dask thread
    when there are members enough."""
    by_time = math.ceil(CHUNK_SECONDS / max(n_steps * STEP_SECONDS, 1e-12))
    return max(1, min(by_time, math.ceil(M / (2 * max(n_threads, 1)))))


def import_on_worker(path, source, key):
    """The generated module: from ``path`` when it holds ``source``, else from a copy of the
    source written under the temp directory (by KEY, so different models never mix)."""
    from .loader import import_generated
    cached = _MODULES.get((path, key))
    if cached is not None:
        return cached
    target = Path(path)
    try:
        visible = target.is_file() and target.read_text() == source
    except OSError:
        visible = False
    if not visible:
        target = Path(tempfile.gettempdir()) / "lagrange-gen-dask" / key / Path(path).name
        if not (target.is_file() and target.read_text() == source):
            target.parent.mkdir(parents=True, exist_ok=True)
            partial = target.with_suffix(".partial")
            partial.write_text(source)
            partial.replace(target)
    module = import_generated(target)
    _MODULES[(path, key)] = module
    return module


def run_chunk(path, source, key, method, q, v, p, t0, h, n_steps, save_every, settings, extra0,
              rows, worker_threads=1):
    """One task: the members (q, v, p) (K, ...) run by ensemble_<method>; returns the output
    dict of ensemble_outputs.allocate_outputs (K members, ``rows`` rows), row 0 of extra from extra0
    (K, n_saved), the members' initial saved fields."""
    from ..jit.api import get_num_threads, max_threads, set_num_threads
    from .ensemble_outputs import allocate_outputs, run_members
    module = import_on_worker(path, source, key)
    run = getattr(module, f"ensemble_{method}")
    K, n = q.shape
    out = allocate_outputs(K, rows, n, extra0.shape[1])
    out["extra"][:, 0] = extra0
    before = get_num_threads()
    set_num_threads(max(1, min(worker_threads, max_threads())))
    try:
        run_members(run, q, v, p, t0, h, n_steps, save_every, settings, out, slice(0, K))
    finally:
        set_num_threads(before)
    return {k: out[k] for k in ("q", "v", "stats", "extra", "last", "status")}


def check_client(client):
    """Refuse, before anything is allocated, a client that cannot take tasks: closed (or
    closing), or not a dask.distributed Client at all; one SimulationError line."""
    status = getattr(client, "status", None)
    if status is None or not hasattr(client, "submit"):
        raise SimulationError(f"client= must be a dask.distributed Client, got "
                              f"{type(client).__name__}")
    if status != "running":
        raise SimulationError(f"the Dask client is {status} (closed clients take no tasks); "
                              f"open a new one, e.g. distributed.Client(cluster)")


def run_on_client(client, module, method, q, v, p, t0, h, n_steps, save_every, settings, out,
                  progress, worker_threads=1):
    """Fill ``out`` (ensemble_outputs.allocate_outputs, M members) through Dask tasks on ``client``."""
    from .fixed_driver import ProgressBar
    path = str(Path(module.__file__).resolve())
    source = Path(path).read_text()
    M, rows = q.shape[0], out["q"].shape[1]
    n_threads = sum(client.nthreads().values())
    size = chunk_size(M, n_steps, n_threads)
    futures = {}
    for start in range(0, M, size):
        s = slice(start, min(M, start + size))
        future = client.submit(run_chunk, path, source, module.KEY, method, q[s], v[s], p[s],
                               t0, h, n_steps, save_every, settings, out["extra"][s, 0].copy(),
                               rows, worker_threads, pure=False)
        futures[future] = s
    from distributed import as_completed
    bar = ProgressBar(M) if progress else None
    done = 0
    for future in as_completed(futures):
        s, chunk = futures[future], future.result()
        for name, values in chunk.items():
            out[name][s] = values
        done += s.stop - s.start
        if bar:
            bar.update(done)
    if bar:
        bar.close()

