"""How many bytes this process can still allocate: the least of the machine's MemAvailable, what
its cgroup's memory limit leaves (cgroup v2 memory.max - memory.current, or v1
memory.limit_in_bytes - memory.usage_in_bytes, on its own cgroup and every one above it) and
what RLIMIT_AS leaves of the address space. Inside a container or a batch job the machine's
MemAvailable can be many times what the job may use: a run sized by it is killed for memory
(rc 137) instead of being refused.

The paths are module constants so that a test can point them at fake files.
"""

from __future__ import annotations

import os
from pathlib import Path

__all__ = ["memory_bounds", "available_memory"]

PROC_MEMINFO = "/proc/meminfo"
PROC_CGROUP = "/proc/self/cgroup"
PROC_STATUS = "/proc/self/status"
#: Where the cgroup v2 hierarchy is mounted; the v1 memory controller is under CGROUP_ROOT/memory.
CGROUP_ROOT = "/sys/fs/cgroup"

#: cgroup v1 writes "no limit" as a huge number (PAGE_COUNTER_MAX pages); anything above this is
#: taken as no limit.
_NO_LIMIT = 1 << 60


def available_memory():
    """Bytes a new allocation can take now (the least of memory_bounds), None when none is known."""
    bounds = memory_bounds()
    return min(bounds.values()) if bounds else None


def memory_bounds():
    """{what: bytes left} for each bound that applies: "MemAvailable", "cgroup limit
    (PATH)", "RLIMIT_AS"; an unreadable or unlimited one is left out."""
    bounds = {}
    meminfo = _meminfo_available()
    if meminfo is not None:
        bounds["MemAvailable"] = meminfo
    for path, left in _cgroup_left():
        bounds[f"cgroup limit ({path})"] = left
    address = _address_space_left()
    if address is not None:
        bounds["RLIMIT_AS"] = address
    return bounds


def _meminfo_available():
    try:
        with open(PROC_MEMINFO) as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:
        return os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError, AttributeError):
        return None


def _cgroup_left():
    """[(limit file, bytes left under it)] for the memory limits of this process's cgroups
    (its own and each ancestor's, v2 and v1)."""
    try:
        lines = Path(PROC_CGROUP).read_text().splitlines()
    except OSError:
        return []
    found = []
    for line in lines:
        parts = line.split(":", 2)
        if len(parts) != 3:
            continue
        _, controllers, path = parts
        if controllers == "":
            found += _limits(Path(CGROUP_ROOT), path, "memory.max", "memory.current")
        elif "memory" in controllers.split(","):
            found += _limits(Path(CGROUP_ROOT) / "memory", path, "memory.limit_in_bytes",
                             "memory.usage_in_bytes")
    return found


def _limits(mount, path, limit_name, usage_name):
    """The limits on ``path`` (as /proc/self/cgroup names it) and its ancestors below
    ``mount``; a cgroup namespace shows the process's own cgroup as the mount itself."""
    directory = mount / path.strip("/")
    if not directory.is_dir():
        directory = mount
    found = []
    while True:
        left = _left(directory / limit_name, directory / usage_name)
        if left is not None:
            found.append((str(directory / limit_name), left))
        if directory == mount or mount not in directory.parents:
            return found
        directory = directory.parent


def _left(limit_file, usage_file):
    try:
        text = limit_file.read_text().strip()
    except OSError:
        return None
    if text == "max":
        return None
    try:
        limit = int(text)
    except ValueError:
        return None
    if limit >= _NO_LIMIT:
        return None
    try:
        usage = int(usage_file.read_text().strip())
    except (OSError, ValueError):
        usage = 0
    return max(limit - usage, 0)


def _address_space_left():
    """RLIMIT_AS (soft) minus this process's address space now (VmSize), None when unlimited."""
    try:
        import resource
        soft, _ = resource.getrlimit(resource.RLIMIT_AS)
    except (ImportError, ValueError, OSError):
        return None
    if soft == resource.RLIM_INFINITY or soft < 0:
        return None
    used = 0
    try:
        with open(PROC_STATUS) as f:
            for line in f:
                if line.startswith("VmSize:"):
                    used = int(line.split()[1]) * 1024
                    break
    except (OSError, ValueError, IndexError):
        pass
    return max(soft - used, 0)
