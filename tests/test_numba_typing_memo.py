"""lagrange_gen.jit.typing_memo: numba's typing of scalar calls remembered within a process.
It must give the same machine code as numba's own typing, and must not answer for calls whose
types it does not cover."""

import json
import os
import subprocess
import sys

from numba import types

from lg_test_support import ROOT
from lagrange_gen.jit import typing_memo as numba_typing_memo
from lagrange_gen.jit.cache import njit


@njit
def _scalar_arithmetic(a, b):
    return a * b + a / b - b ** 2 + (a < b)


def test_used_by_the_package_njit():
    before = numba_typing_memo.stats()
    assert _scalar_arithmetic(3.0, 2.0) == 3.0 * 2.0 + 3.0 / 2.0 - 4.0 + 0
    after = numba_typing_memo.stats()
    assert after["hits"] + after["misses"] > before["hits"] + before["misses"]


def test_calls_on_arrays_or_literals_go_to_numba_unchanged():
    import operator

    from numba.core.registry import cpu_target
    context = cpu_target.typing_context
    context.refresh()
    fnty = context.resolve_value_type(operator.add)
    restore = numba_typing_memo.activate()          # as jit.speedups.compiling does
    try:
        _resolve_through_the_memo(context, fnty)
    finally:
        restore()


def _resolve_through_the_memo(context, fnty):
    before = numba_typing_memo.stats()
    array = types.Array(types.float64, 1, "C")
    assert context.resolve_function_type(fnty, (array, array), {}).return_type == array
    assert context.resolve_function_type(fnty, (types.IntegerLiteral(2), types.float64), {}) is not None
    after = numba_typing_memo.stats()
    assert (after["hits"], after["misses"]) == (before["hits"], before["misses"])
    f64 = (types.float64, types.float64)
    first = context.resolve_function_type(fnty, f64, {})
    second = context.resolve_function_type(fnty, f64, {})
    assert first == second and first.return_type == types.float64
    assert numba_typing_memo.stats()["hits"] >= after["hits"] + 1


# Compiles every kernel of the cart pendulum and of the double pendulum (as generated in
# generated/) in a fresh process with an empty numba cache and prints a hash of their assembly.
# LAGRANGE_GEN_NATIVE=0: a kernel called from Python otherwise runs its native (llvmlite) twin
# and numba, whose typing is under test, compiles nothing.
_ASM = """
import hashlib, json, os, sys
from lagrange_gen.jit import typing_memo as numba_typing_memo
from lagrange_gen.run.loader import kernel_call_args, import_generated
h = hashlib.sha256()
for stem in ("cart_pendulum", "double_pendulum"):
    mod = import_generated(os.path.join(sys.argv[1], "generated", stem + ".py"))
    args = kernel_call_args(mod)
    for name in tuple(mod.KERNELS) + ("forward_dynamics",):
        kernel = getattr(mod, name)
        kernel(*args[name])
        for sig, asm in sorted(kernel.inspect_asm().items(), key=str):
            h.update(name.encode() + asm.encode())
print(json.dumps({"asm": h.hexdigest(), "stats": numba_typing_memo.stats()}))
"""


def _compile_in_fresh_process(tmp_path, memo):
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / f"cache_{memo}"), LAGRANGE_GEN_NATIVE="0",
               LAGRANGE_GEN_SPEEDUPS="all" if memo == "1" else "-typing_memo")
    out = subprocess.run([sys.executable, "-c", _ASM, str(ROOT)], capture_output=True, text=True,
                         env=env, timeout=600)
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout.strip().splitlines()[-1])


def test_kernels_compile_to_the_same_machine_code_with_and_without(tmp_path):
    with_memo = _compile_in_fresh_process(tmp_path, "1")
    without = _compile_in_fresh_process(tmp_path, "0")
    assert with_memo["stats"]["hits"] > 100
    assert without["stats"]["hits"] == 0
    assert with_memo["asm"] == without["asm"]
