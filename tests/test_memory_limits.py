"""The memory checks honour the process's limits, not only the machine's MemAvailable: cgroup v2
and v1 memory limits (faked here with files) and RLIMIT_AS; ensembles and grids are sized
before anything is allocated (issue 34, item 3)."""

import subprocess
import sys

import numpy as np
import pytest

import lagrange_gen as lg
from lagrange_gen.run import checks as run_checks
from lagrange_gen.run import memory

GIB = 1 << 30


@pytest.fixture
def fake_cgroup(tmp_path, monkeypatch):
    """Return a function writing fake /proc/self/cgroup and limit files; the checks read them."""
    root = tmp_path / "cgroup"
    monkeypatch.setattr(memory, "PROC_CGROUP", str(tmp_path / "proc_cgroup"))
    monkeypatch.setattr(memory, "CGROUP_ROOT", str(root))

    def make(version, limit, usage, where="job.slice/run"):
        if version == 2:
            (tmp_path / "proc_cgroup").write_text(f"0::/{where}\n")
            d = root / where
            names = ("memory.max", "memory.current")
        else:
            (tmp_path / "proc_cgroup").write_text(f"4:memory:/{where}\n1:cpu:/\n")
            d = root / "memory" / where
            names = ("memory.limit_in_bytes", "memory.usage_in_bytes")
        d.mkdir(parents=True, exist_ok=True)
        (d / names[0]).write_text(f"{limit}\n")
        (d / names[1]).write_text(f"{usage}\n")
        return d
    return make


@pytest.mark.parametrize("version", [1, 2])
def test_available_memory_is_at_most_what_the_cgroup_limit_leaves(fake_cgroup, version):
    fake_cgroup(version, limit=int(1.5 * GIB), usage=GIB // 2)
    assert run_checks.available_memory() <= GIB


def test_a_limit_on_a_parent_cgroup_counts(fake_cgroup, tmp_path):
    fake_cgroup(2, limit="max", usage=0)
    parent = tmp_path / "cgroup" / "job.slice"
    (parent / "memory.max").write_text(f"{GIB}\n")
    (parent / "memory.current").write_text("0\n")
    assert run_checks.available_memory() <= GIB


@pytest.mark.parametrize("version, limit", [(2, "max"), (1, 9223372036854771712)])
def test_no_limit_leaves_mem_available(fake_cgroup, version, limit):
    fake_cgroup(version, limit=limit, usage=0)
    assert "MemAvailable" in memory.memory_bounds()
    assert not any(k.startswith("cgroup") for k in memory.memory_bounds())


def test_simulate_inside_a_small_cgroup_is_refused_before_allocating(fake_cgroup, generated):
    """1e8 saved steps in a 1.5 GiB cgroup: refused in one line (it was killed, rc 137)."""
    fake_cgroup(2, limit=int(1.5 * GIB), usage=GIB // 4)
    with pytest.raises(lg.SimulationError) as err:
        lg.simulate(generated("damped_oscillator"), "rk4", q0=[1.0], t_end=1e5, h=1e-3)
    text = str(err.value)
    assert "\n" not in text and "of memory" in text and "cgroup limit" in text


def test_rlimit_as_bounds_available_memory():
    code = ("import resource; from lagrange_gen.run import checks, memory;"
            "used = [int(l.split()[1]) * 1024 for l in open('/proc/self/status') "
            "if l.startswith('VmSize:')][0];"
            "resource.setrlimit(resource.RLIMIT_AS, (used + 2**30, resource.RLIM_INFINITY));"
            "print(checks.available_memory(), 'RLIMIT_AS' in memory.memory_bounds())")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    left, named = out.stdout.split()
    assert int(left) <= 2**30 and named == "True"


def test_an_ensemble_of_a_billion_members_is_refused_before_any_allocation(generated):
    """params given as a zero-stride (10**9,) view: nothing is allocated by the caller; the
    ensemble's own tables (16 GB for q0 alone) must be refused, not attempted."""
    members = np.broadcast_to(1.0, (10**9,))
    with pytest.raises(lg.SimulationError) as err:
        lg.ensemble(generated("damped_oscillator"), "rk4", params={"m": members}, t_end=0.01,
                    h=0.01)
    text = str(err.value)
    assert "\n" not in text and "1000000000 members" in text and "of memory" in text


def test_a_grid_too_large_for_memory_is_refused_at_once():
    with pytest.raises(lg.SimulationError) as err:
        lg.grid(a=np.arange(10**5), b=np.arange(10**5))
    text = str(err.value)
    assert "\n" not in text and "10000000000 points" in text and "of memory" in text


def test_an_ensemble_of_no_members_is_refused(generated):
    with pytest.raises(lg.SimulationError) as err:
        lg.ensemble(generated("damped_oscillator"), "rk4", q0=np.zeros((0, 1)), t_end=0.1, h=0.01)
    assert "\n" not in str(err.value) and "0 members" in str(err.value)


def test_a_step_longer_than_the_run_warns(generated):
    """h = 1 > t_end = 0.5 ran to t = 1 without a word (issue 34, item 8)."""
    with pytest.warns(UserWarning, match=r"h = 1 is longer than the run .* ends at t = 1, past "
                                         r"t_end = 0\.5"):
        traj = lg.simulate(generated("damped_oscillator"), "rk4", q0=[1.0], t_end=0.5, h=1.0)
    assert traj.t[-1] == 1.0 and "longer than the run" in traj.warnings[0]
