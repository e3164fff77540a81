"""lagrange_gen.jit.inline_copy: numba's inliner copying a callee's scope once per IR, not once
per block. The copies must be what numba's own block-by-block deepcopy gives, and a stepper
compiled with and without it must run the same floating-point operations."""

import copy
import json
import os
import subprocess
import sys

import numpy as np
from numba.core import inline_closurecall, ir
from numba.core.compiler import run_frontend

import lagrange_gen.steppers  # noqa: F401
from lagrange_gen.jit import inline_copy as numba_inline_copy
from lg_test_support import ROOT


def _branchy(x, n):
    s = 0.0
    for i in range(n):
        if x[i] > 0.0:
            s += x[i] * 2.0
        else:
            s -= x[i]
    return s


def test_supported_and_not_installed_outside_a_compile():
    assert numba_inline_copy.unsupported() is None
    assert inline_closurecall.copy is copy


def test_block_copies_equal_numbas_own_and_share_one_scope_copy():
    func_ir = run_frontend(_branchy)
    assert len(func_ir.blocks) > 3
    copier = numba_inline_copy._BlockCopier(ir)
    ours = {label: copier.deepcopy(block) for label, block in func_ir.blocks.items()}
    theirs = {label: copy.deepcopy(block) for label, block in func_ir.blocks.items()}
    scope = next(iter(func_ir.blocks.values())).scope
    for label in func_ir.blocks:
        assert ours[label] == theirs[label]                        # ir.Block equality: body, scope
        assert [str(s) for s in ours[label].body] == [str(s) for s in theirs[label].body]
    scopes = {id(block.scope) for block in ours.values()}
    assert len(scopes) == 1 and ours[next(iter(ours))].scope is not scope
    assert ours[next(iter(ours))].scope == scope


def test_a_scope_that_changed_is_copied_again():
    func_ir = run_frontend(_branchy)
    copier = numba_inline_copy._BlockCopier(ir)
    first, second = list(func_ir.blocks.values())[:2]
    before = copier.deepcopy(first)
    first.scope.redefine("added_after_the_first_copy", loc=first.loc)
    after = copier.deepcopy(second)
    assert after.scope is not before.scope
    assert "added_after_the_first_copy" in after.scope.localvars._con
    assert "added_after_the_first_copy" not in before.scope.localvars._con


_RUN = """
import json, sys
import numpy as np
sys.path.insert(0, sys.argv[1])
import cart_pendulum as mod
from lagrange_gen.jit import inline_copy
from lagrange_gen.steppers.core.layout import N_STATS
from lagrange_gen.steppers.core import registry
from lagrange_gen.steppers.core.method_spec import make_settings
n, rows = 2, 2
out = (np.empty(rows), np.empty((rows, n)), np.empty((rows, n)), np.empty((rows, N_STATS)),
       np.empty((rows, 0)), np.empty(2 * n + 3), np.empty((0, 3 + 2 * n)))
status, done, _ = mod.run_symplectic_euler(
    np.array([0.1, 1.0]), np.array([0.3, -0.2]), 0.0, 0.01, 300, 300, mod.DEFAULT_PARAMS.copy(),
    make_settings(registry.spec("symplectic_euler"), {}), *out)
print(json.dumps({"copier": inline_copy.stats["blocks"] > 0, "status": int(status),
                  "last": [float(x).hex() for x in out[5]]}))
"""


def test_a_stepper_compiled_with_and_without_it_runs_the_same_operations(tmp_path):
    """The cart pendulum's own symplectic_euler glue compiled in two fresh processes (each with
    an empty numba cache), numba's copy and ours: the final state must be equal bit for bit."""
    results = {}
    for setting in ("0", "1"):
        env = dict(os.environ, LAGRANGE_GEN_SPEEDUPS="all" if setting == "1" else "-inline_copy",
                   NUMBA_CACHE_DIR=str(tmp_path / f"cache{setting}"))
        done = subprocess.run([sys.executable, "-c", _RUN, str(ROOT / "generated")], env=env,
                              capture_output=True, text=True, timeout=600)
        assert done.returncode == 0, done.stderr[-2000:]
        results[setting] = json.loads(done.stdout.strip().splitlines()[-1])
    assert results["0"]["copier"] is False and results["1"]["copier"] is True
    assert results["0"]["status"] == results["1"]["status"] == 0
    assert results["0"]["last"] == results["1"]["last"]
    assert np.isfinite([float.fromhex(x) for x in results["1"]["last"]]).all()
