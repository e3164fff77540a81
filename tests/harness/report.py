"""The harness's counts for the terminal summary and --harness-summary, gathered from every
pytest-xdist worker (each worker draws and checks its share of the models)."""

from . import profiles
from .check import CHECKED, STATS


#: The profile the workers ran (the controller does not run tests/harness/conftest.py, which
#: selects it); None in a run without workers.
_WORKER_PROFILE = []


def summary():
    """{profile, models, failed_models, kernel_checks, kinds: {kind: {mode: count}}}."""
    kinds = {}
    for (kind, mode), count in sorted(CHECKED.items()):
        kinds.setdefault(kind, {})[mode] = count
    profile = _WORKER_PROFILE[0] if _WORKER_PROFILE else profiles.current()["name"]
    return {"profile": profile, "models": STATS["models"],
            "failed_models": STATS["failed models"], "kernel_checks": sum(CHECKED.values()), "kinds": kinds}


def worker_counts():
    """This process's raw counts, as plain JSON-able data for xdist's workeroutput."""
    return {"checked": [[kind, mode, count] for (kind, mode), count in CHECKED.items()],
            "stats": dict(STATS), "profile": profiles.current()["name"]}


def add_worker_counts(counts):
    """Add a worker's worker_counts() to this process's counts (on the xdist controller)."""
    for kind, mode, count in counts["checked"]:
        CHECKED[(kind, mode)] += count
    STATS.update(counts["stats"])
    if not _WORKER_PROFILE:
        _WORKER_PROFILE.append(counts["profile"])
