"""Make numba's IR-level inlining copy a callee's variable scope once, not once per block.

Every ``inline="always"`` call numba inlines (numba.core.inline_closurecall.InlineWorker.
inline_ir) copies the callee's IR twice, block by block, each block with ``copy.deepcopy`` and no
shared memo. All blocks of a function share one Scope, which holds every variable of the
function, so each block's copy copies that whole scope again: quadratic in the size of the
callee. The steppers inline their Newton solves into the step and the step into the stepping
loop, so the callees are large. In a profile (cProfile, cart pendulum, the specialized
run_verlet) deepcopy takes about nine tenths of the inlining pass, and the pass over a third of
the compile.

``install()`` replaces the ``copy`` module that inline_closurecall sees by a stand-in whose
``deepcopy`` of an ir.Block (the one call numba makes there) reuses one copy of the scope for
consecutive blocks of the same scope, so the copied blocks share one scope again, as the blocks they
were copied from do. Every other attribute is the real ``copy`` module's. The inlining pass then
takes a fraction of its time (compile time with and without: ``lagrange-gen bench compile``,
reports/compile.md). The compiled code is the same: tests/test_numba_inline_copy.py compares the
copies with numba's own, and a stepper compiled in two fresh processes, with and without it, bit for
bit.

Active only while a lagrange_gen function compiles (jit.speedups.compiling), when
$LAGRANGE_GEN_SPEEDUPS selects inline_copy and inline_closurecall still makes exactly that call
(its source is checked, ``unsupported``).
"""

from __future__ import annotations

import copy
import inspect

#: The statement of numba's copy_ir this module speeds up; no install if the source lacks it.
_EXPECTED_CALL = "copy.deepcopy(the_ir.blocks[block_label])"


class _BlockCopier:
    """Stands in for the ``copy`` module inside numba.core.inline_closurecall."""

    def __init__(self, ir_module):
        self._ir = ir_module
        # (source scope, number of its variables when copied, its copy) of the last block copied
        self._last = (None, -1, None)

    def __getattr__(self, name):
        return getattr(copy, name)

    def deepcopy(self, x, memo=None):
        """copy.deepcopy, except that an ir.Block copied without a memo gets the scope copy of
        the previous block when both blocks share a scope that has not changed since (copy_ir
        copies the blocks of one IR one after another, nothing in between)."""
        if memo is not None or not isinstance(x, self._ir.Block):
            return copy.deepcopy(x, memo)
        stats["blocks"] += 1
        scope = x.scope
        size = len(scope.localvars._con)
        source, source_size, scope_copy = self._last
        if source is not scope or source_size != size:
            scope_copy = copy.deepcopy(scope)
            self._last = (scope, size, scope_copy)
        return copy.deepcopy(x, {id(scope): scope_copy})


def unsupported():
    """None when numba's inliner copies blocks as the copier expects, else why not."""
    from numba.core import inline_closurecall, ir
    if not (inline_closurecall.copy is copy or isinstance(inline_closurecall.copy, _BlockCopier)):
        return "numba.core.inline_closurecall.copy is not the copy module"
    if _EXPECTED_CALL not in inspect.getsource(inline_closurecall.InlineWorker.inline_ir):
        return "numba's InlineWorker.inline_ir no longer deep-copies block by block"
    if not hasattr(ir.Scope(None, ir.Loc("", 0)).localvars, "_con"):
        return "numba's ir.Scope.localvars has no _con"
    return None


#: Blocks copied by the copier in this process (the tests tell from it that it ran).
stats = {"blocks": 0}


def activate():
    """Put the block copier in numba's inliner; returns the undo."""
    from numba.core import inline_closurecall, ir
    original = inline_closurecall.copy
    inline_closurecall.copy = _BlockCopier(ir)

    def restore():
        inline_closurecall.copy = original

    return restore
