"""numba's on-disk cache of the package's own ``cache=True`` functions (lagrange_gen.jit).

numba keys a cache entry on the text of the file that defines the function, but the compiled
code also holds every function it calls, from other files. constrained.solve_rows (cache=True)
calls linalg.cholesky_solve_inplace: when steppers/core/linalg.py changed and constrained.py did not, numba
loaded the old solve_rows, with the old solve inside, without a word. That is how the portable
glue compiled on one checkout and the specialized glue compiled on a clean clone came to differ
in the last bit (CI of 2026-11-26). lagrange_gen.jit keys these entries on every package file
the function's module imports, transitively (sources.source_closure)."""

import importlib
import json
import os
import pkgutil
import shutil
import subprocess
import sys
from pathlib import Path

import lagrange_gen
from lagrange_gen.jit import cache as jit

PACKAGE = Path(lagrange_gen.__file__).resolve().parent

# Solves H y = J_k^T for the rows of J with H = diag(4, 9) through constrained.solve_rows and
# prints the rows and how numba's cache served the call.
_PROBE = """
import json, sys
sys.path.insert(0, sys.argv[1])
import numpy as np
import lagrange_gen
assert lagrange_gen.__file__.startswith(sys.argv[1]), lagrange_gen.__file__
from lagrange_gen.steppers.core.constrained import solve_rows
L = np.array([[2.0, 0.0], [0.0, 3.0]])
J = np.array([[1.0, 1.0]])
Y = np.zeros((1, 2))
solve_rows(L, J, Y)
print(json.dumps({"Y": Y.tolist(), "hits": sum(solve_rows.stats.cache_hits.values()),
                  "misses": sum(solve_rows.stats.cache_misses.values())}))
"""

# Appended to the copy's steppers/core/linalg.py: a cholesky_solve_inplace that gives another answer, as an
# edit of steppers/core/linalg.py (and of no other file) would.
_CHANGED_SOLVE = """

@njit(cache=True, _nrt=False)
def cholesky_solve_inplace(L, b):
    for i in range(b.shape[0]):
        b[i] = -1.0
"""


def _probe(root):
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    out = subprocess.run([sys.executable, "-c", _PROBE, str(root)], capture_output=True,
                         text=True, env=env, timeout=300)
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout.strip().splitlines()[-1])


def test_a_change_in_a_callee_file_recompiles_the_cached_caller(tmp_path):
    shutil.copytree(PACKAGE, tmp_path / "lagrange_gen",
                    ignore=shutil.ignore_patterns("__pycache__", "*.nb[ic]"))
    first = _probe(tmp_path)
    assert first["Y"] == [[0.25, 1.0 / 9.0]] and first["misses"] == 1
    again = _probe(tmp_path)                 # nothing changed: the entry serves a new process
    assert again == {"Y": first["Y"], "hits": 1, "misses": 0}
    linalg = tmp_path / "lagrange_gen" / "steppers" / "core" / "linalg.py"
    linalg.write_text(linalg.read_text() + _CHANGED_SOLVE)
    changed = _probe(tmp_path)
    assert changed["Y"] == [[-1.0, -1.0]], "solve_rows came from the cache of the old steppers/core/linalg.py"
    assert changed["misses"] == 1


def test_every_cached_package_function_uses_the_closure_key():
    """No package function is cached by plain numba.njit(cache=True), whose entry would survive
    a change in the files it calls into."""
    plain = []
    for info in pkgutil.walk_packages([str(PACKAGE)], "lagrange_gen."):
        module = importlib.import_module(info.name)
        for name, value in vars(module).items():
            cache = getattr(value, "_cache", None)
            if getattr(value, "py_func", None) is None or cache is None:
                continue
            if value.py_func.__module__ != info.name or type(cache).__name__ == "NullCache":
                continue
            if not isinstance(cache, jit.closure_keyed_cache_class()):
                plain.append(f"{info.name}.{name}")
    assert not plain, f"cached with numba's file-only key: {plain}"


def test_the_key_covers_the_imports_of_the_module():
    stamp = jit.closure_stamp(PACKAGE / "steppers" / "core" / "constrained.py")
    assert {"steppers/core/constrained.py", "steppers/core/linalg.py",
            "steppers/core/legendre.py"} <= set(json.loads(stamp))
    assert jit.closure_stamp(PACKAGE / "steppers" / "core" / "linalg.py") != stamp


def test_a_moved_project_says_so_not_unreadable(tmp_path):
    """Generated modules are imported under a name made from their path; after the project
    folder moved, numba's entries name the old module. The warning said the cache was
    "unreadable (ModuleNotFoundError ...)" (issue 34, item 8)."""
    models = Path(__file__).resolve().parent.parent / "models"
    run = ("import sys, numpy as np; from lagrange_gen.run.loader import import_generated;"
           "m = import_generated(sys.argv[1]);"
           "print(m.energy(np.ones(1), np.zeros(1), 0.0, m.DEFAULT_PARAMS.copy()))")
    make = ("import sys; from lagrange_gen.codegen import generate_model;"
            "generate_model(sys.argv[1], sys.argv[2], methods=['rk4'])")
    # numba's cache beside the module (its __pycache__ moves with the folder): with
    # NUMBA_CACHE_DIR the entries stay under the old path and the moved module simply misses.
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    subprocess.run([sys.executable, "-c", make, str(models / "damped_oscillator.py"),
                    str(tmp_path / "old")], check=True, timeout=300, env=env)
    subprocess.run([sys.executable, "-c", run, str(tmp_path / "old" / "damped_oscillator.py")],
                   check=True, timeout=300, capture_output=True, env=env)
    (tmp_path / "old").rename(tmp_path / "new")
    out = subprocess.run([sys.executable, "-c", run, str(tmp_path / "new" / "damped_oscillator.py")],
                         check=True, timeout=300, capture_output=True, text=True, env=env)
    assert out.stdout.strip() == "0.5"
    assert "unreadable" not in out.stderr and "moved" in out.stderr, out.stderr
    assert len(out.stderr.strip().splitlines()) == 1, out.stderr
