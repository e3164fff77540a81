"""Profiles of the differential harness: how many models each test draws.

``ci`` (default) keeps the harness near a minute on 2 cores; ``thorough`` (pytest option
``--thorough``, or ``lagrange-gen bench harness``) draws hundreds of models. Both are
derandomized with no example database, so a run is reproducible. Measured here: an example run
as Python (derive, emit, reference, 3-4 states) costs ~0.8 s of CPU, compiling its kernels with
numba 1.5-3 s more, so most examples run the printed source as Python (py_func) and a few per
model class compile every kernel as well (ci: 36 models, ~30 s CPU; thorough: 341 models,
~280 s CPU). No shrinking: with an example costing about a second, hypothesis spent its
five-minute shrinking budget without progress; a failure prints the drawn model as it is.
"""

from __future__ import annotations

from hypothesis import HealthCheck, Phase, settings

PROFILES = {
    # examples per model class: run as py_func / compiled (njit and py_func); states per model;
    # spatial trees (test_spatial_trees.py): 3-4 bodies against the reference (py_func; njit),
    # 5-10 bodies against the invariants (py_func)
    "ci": {"py_func": 6, "njit": 1, "native": 3, "states": 3, "trees": 1, "trees_njit": 0,
           "large_trees": 1},
    "thorough": {"py_func": 60, "njit": 8, "native": 30, "states": 4, "trees": 30, "trees_njit": 1,
                 "large_trees": 10},
}
_current = {"name": "ci", "count_only": False}


def select(name, count_only=False):
    """Use profile ``name``; count_only: record failing examples instead of failing (--printer-bug)."""
    _current.update(name=name, count_only=count_only)


def current():
    return dict(PROFILES[_current["name"]], name=_current["name"], count_only=_current["count_only"])


def hypothesis_settings(mode):
    """Hypothesis settings of the tests running kernels in ``mode`` ("py_func", "njit" or
    "native"; or a
    count of the spatial-tree tests: "trees", "trees_njit", "large_trees")."""
    return settings(max_examples=max(1, current()[mode]), derandomize=True, database=None, deadline=None,
                    phases=(Phase.explicit, Phase.generate), print_blob=False,
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large,
                                           HealthCheck.filter_too_much])
