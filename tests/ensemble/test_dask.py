"""lagrange_gen.ensemble(..., client=...) through a dask.distributed LocalCluster of two worker
processes returns the same arrays as the local run; a worker that cannot see the module's path
imports the source shipped with the task."""

import tempfile
from pathlib import Path

import numpy as np
import pytest

import lagrange_gen as lg
from lagrange_gen.codegen import generate_model
from lagrange_gen.run.ensemble_dask import chunk_size, import_on_worker
from lagrange_gen.run.loader import import_generated

distributed = pytest.importorskip("distributed")
MODELS = Path(__file__).resolve().parents[2] / "models"


@pytest.fixture(scope="module")
def cart(tmp_path_factory):
    out = tmp_path_factory.mktemp("ensemble_dask_gen")
    return import_generated(generate_model(MODELS / "cart_pendulum.py", out,
                                           methods=["explicit_euler"]).path)


def test_local_cluster_returns_the_same_arrays(cart):
    rng = np.random.default_rng(3)
    M = 40
    q0, v0 = rng.uniform(-0.5, 0.5, (M, 2)), rng.uniform(-1, 1, (M, 2))
    v0[5] = [0.0, 40.0]                     # one failing member travels through Dask too
    kwargs = dict(q0=q0, v0=v0, params={"k": rng.uniform(5, 15, M)}, t_end=2.0, h=0.01,
                  save_every=3, blowup_bound=60.0)
    local = lg.ensemble(cart, "explicit_euler", **kwargs)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        remote = lg.ensemble(cart, "explicit_euler", client=client, **kwargs)
    for name in ("q", "v", "energy", "newton_iters", "status", "steps_done", "fail_time"):
        np.testing.assert_array_equal(getattr(remote, name), getattr(local, name))
    assert remote.failures() == local.failures() and len(local.failures()) == 1


def test_worker_without_the_path_imports_the_shipped_source(cart, tmp_path):
    source = Path(cart.__file__).read_text()
    missing = str(tmp_path / "elsewhere" / Path(cart.__file__).name)
    module = import_on_worker(missing, source, cart.KEY)
    copy = Path(tempfile.gettempdir()) / "lagrange-gen-dask" / cart.KEY / Path(missing).name
    assert copy.read_text() == source and Path(module.__file__).read_text() == source
    assert Path(module.__file__) != Path(missing) and module.KEY == cart.KEY


def test_chunks_are_long_enough_but_feed_every_thread():
    assert chunk_size(10_000, 10_000, 2) == 167         # 0.5 s of 3e-7 s steps
    assert chunk_size(40, 200, 2) == 10                 # two tasks per thread


def test_a_closed_client_is_one_line(cart):
    """It gave AttributeError: 'NoneType' object has no attribute 'ncores' (issue 34, item 8)."""
    client = distributed.Client(processes=False, n_workers=1, threads_per_worker=1,
                                dashboard_address=None)
    client.close()
    with pytest.raises(lg.SimulationError) as err:
        lg.ensemble(cart, "explicit_euler", q0=np.zeros((4, 2)), t_end=0.1, h=0.01, client=client)
    text = str(err.value)
    assert "\n" not in text and "client" in text and "closed" in text, text
