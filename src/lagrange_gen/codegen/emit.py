"""Emit one KernelSpec as numba source: loads, one CSE pass, stores (deterministic, no I/O).

The shape of the emitted code is chosen for numba's compile time, which on a large model is
mostly LLVM's (the 16-link pendulum's dynamics kernel has hundreds of lines; first compile of
the kernels against the number of links: ``lagrange-gen bench scale``, reports/scale.md):

* Every input entry is loaded once into a local (``q_3 = q[3]``) before anything is stored.
  LLVM cannot prove that the output arrays do not alias the inputs, so an expression reading
  ``q[3]`` after a store must reload it, and memory-dependence analysis over hundreds of
  interleaved loads and stores would be most of LLVM's time.
* Large 2-D outputs (more than FLAT_VIEW_MIN entries) are written through a flat view
  (``H_f = H.reshape(n * n)``): one store per entry instead of numba's 2-D index arithmetic,
  which halves what remains of LLVM's time. Outputs must therefore be C-contiguous, which
  every caller in the package passes. Small ones are written as ``H[i, j]``: the reshape is a
  run-time call (numba_attempt_nocopy_reshape) on every kernel call, a few ns each, which on
  the cart pendulum would be about a third of symplectic Euler's step. At n = 8 the direct
  stores gain nothing at run time and cost about 10 % more compile time, hence the threshold
  (n <= 4 direct).
* Structurally zero entries (zero for every state, decided symbolically) are not computed: a
  few are stored as ``0.0``; more are written by a loop over a module constant of flat indices.
* Symmetric outputs compute the upper triangle and store each value to both places.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import symengine as se

from .cse import cse
from .printer import KernelPrinter, print_native
from .spec import KernelSpec

#: More structural zeros than this in one output are written by a loop, fewer as statements.
ZERO_LOOP_MIN = 8
#: 2-D outputs with more entries than this are written through a flat view (module docstring).
FLAT_VIEW_MIN = 16


@dataclass
class KernelText:
    """The source of one kernel: module-level constants it uses and its function text."""

    name: str
    constants: list = field(default_factory=list)
    function: str = ""
    n_zero: int = 0          # structurally zero entries (not computed)
    n_entries: int = 0       # all computed-or-zero entries (mirrored symmetric ones counted once)
    n_temps: int = 0         # CSE temporaries
    cse_exprs: list = field(default_factory=list)   # temporaries' and outputs' CSE'd sympy exprs


@dataclass
class _Entry:
    out: object              # Output, or None for the scalar result
    i: int
    j: int
    expr: object


def _entries(spec: KernelSpec):
    """One entry per value the kernel produces; symmetric outputs list the upper triangle."""
    entries = []
    for out in spec.outputs:
        rows, cols = out.matrix.shape
        for i in range(rows):
            for j in range(cols):
                if not (out.symmetric and j < i):
                    entries.append(_Entry(out, i, j, out.matrix[i, j]))
    if spec.result is not None:
        entries.append(_Entry(None, 0, 0, spec.result))
    return entries


def _flat_name(out):
    return out.name if out.is_vector else f"{out.name}_f"


def _through_view(out):
    """A 2-D output written through its flat view (large), rather than as out[i, j]."""
    rows, cols = out.matrix.shape
    return not out.is_vector and rows * cols > FLAT_VIEW_MIN


def _flat(entry):
    """Flat indices an entry is stored at (two for an off-diagonal symmetric entry)."""
    out, i, j = entry.out, entry.i, entry.j
    cols = out.matrix.shape[1]
    return [i * cols + j] + ([j * cols + i] if out.symmetric and i != j else [])


def local_name(out_name, i, j=None):
    """The local variable a ``local`` output's entry is assigned to: H_0_1, rhs_1."""
    return f"{out_name}_{i}" if j is None else f"{out_name}_{i}_{j}"


def _targets(entry):
    """Store targets of an entry: rhs[3] for a vector, H[1, 2] for a small matrix, H_f[7]
    (flat view) for a large one; two for an off-diagonal symmetric entry; one local variable
    for a ``local`` output."""
    out = entry.out
    if out.local:
        return [local_name(out.name, entry.i, None if out.is_vector else entry.j)]
    if out.is_vector or _through_view(out):
        return [f"{_flat_name(out)}[{k}]" for k in _flat(entry)]
    cols = out.matrix.shape[1]
    return [f"{out.name}[{k // cols}, {k % cols}]" for k in _flat(entry)]


def _zero_lines(spec, zeros):
    """Statements and module constants that write the structural zeros of each output."""
    lines, constants = [], []
    for out in spec.outputs:
        if out.local:
            lines += [f"    {_targets(e)[0]} = 0.0" for e in zeros if e.out is out]
            continue
        index = sorted(k for e in zeros if e.out is out for k in _flat(e))
        if not index:
            continue
        size = out.matrix.shape[0] * out.matrix.shape[1]
        if not out.is_vector and not _through_view(out):
            cols = out.matrix.shape[1]
            lines += [f"    {out.name}[{k // cols}, {k % cols}] = 0.0" for k in index]
        elif len(index) < ZERO_LOOP_MIN:
            lines += [f"    {_flat_name(out)}[{k}] = 0.0" for k in index]
        elif len(index) == size:
            lines += [f"    for k in range({size}):", f"        {_flat_name(out)}[k] = 0.0"]
        else:
            const = f"_ZEROS_{spec.name.upper()}_{out.name.upper()}"
            constants.append(f"{const} = np.array({index!r}, dtype=np.int64)")
            lines += [f"    for k in {const}:", f"        {_flat_name(out)}[k] = 0.0"]
    return lines, constants


def _load_lines(used, order):
    """``q_3 = q[3]`` for every placeholder the body uses, in argument order."""
    return [f"    {name} = {source}" for name, source in order if name in used]


def render_kernel(spec: KernelSpec, inputs) -> KernelText:
    """One ``@njit(**KERNEL_OPTIONS)`` kernel (lagrange_gen.jit.KERNEL_OPTIONS: cached, no
    allocation, so no reference counting, which would cost every call from a stepper; numpy's
    error model, so a division by zero gives inf/NaN, which the steppers report as NON_FINITE,
    instead of raising ZeroDivisionError inside the jitted loop).

    inputs: codegen.printer.Inputs of the model (symbol -> placeholder and load statement).
    """
    if spec.columns:
        return render_column_kernel(spec, inputs)
    entries = _entries(spec)
    live = [e for e in entries if e.expr != 0]
    zeros = [e for e in entries if e.expr == 0 and e.out is not None and not e.out.accumulate]
    if inputs.graph is None:
        temps, reduced = cse([e.expr for e in live], inputs.rename)
        printer = KernelPrinter().doprint
        used = set()
        for expr in [e for _, e in temps] + list(reduced):
            used |= {s.name for s in expr.free_symbols}
    else:
        temps, reduced = graph_body(inputs, [e.expr for e in live])
        printer = print_native
        used = {s.name for _, e in temps for s in e.free_symbols}
        used |= {s.name for e in reduced for s in e.free_symbols}
    body = [f"    {name} = {printer(e)}" for name, e in temps]
    result = "0.0"
    stores = []
    for entry, value in zip(live, reduced):
        text = printer(value)
        if entry.out is None:
            result = text
        else:
            op = "+=" if entry.out.accumulate else "="
            stores.append(f"    {' = '.join(_targets(entry))} {op} {text}")
    zero_lines, constants = _zero_lines(spec, zeros)
    views = [f"    {o.name}_f = {o.name}.reshape({o.matrix.shape[0] * o.matrix.shape[1]})"
             for o in spec.outputs if _through_view(o) and not o.local]
    args = ", ".join(spec.signature)
    lines = ['@njit(**KERNEL_OPTIONS)', f"def {spec.name}({args}):",
             f'    """{_doc(spec, zeros, entries)}"""']
    lines += [f"    {line}" for line in spec.prologue]
    lines += _load_lines(used, inputs.loads(spec.args)) + body + views + stores + zero_lines
    lines += [f"    {line}" for line in spec.epilogue]
    if spec.result is not None:
        lines.append(f"    return {result}")
    elif len(lines) == 3:
        lines.append("    return None")
    return KernelText(spec.name, constants, "\n".join(lines), n_zero=len(zeros),
                      n_entries=len(entries), n_temps=len(temps),
                      cse_exprs=[e for _, e in temps] + list(reduced))


def render_column_kernel(spec: KernelSpec, inputs) -> KernelText:
    """A Jacobian kernel of a graph model as loops over its columns: the graph nodes that do not
    depend on the seeds once, then for each output ``for k in range(cols)`` with seed_i = 1.0
    where i == k, the tangent nodes and the stores of column k (an output without seeds is a
    vector stored outside the loops); then the spec's epilogue. numba's compile time follows
    the operations in the text, and the loop holds one tangent pass where the written-out
    Jacobian holds cols of them; the run time is the same number of operations."""
    graph = inputs.graph
    placeholders = _placeholder_map(inputs)
    seeds = {s for _, column_seeds, _ in spec.columns for s in column_seeds}
    everything = [e for _, _, column in spec.columns for e in column]
    outside = [(s, d) for s, d in graph.used_nodes(everything) if not (graph.inputs_of(s) & seeds)]
    printed, used = [], set()

    def text(expr):
        expr = placeholders(expr)
        used.update(s.name for s in expr.free_symbols)
        return print_native(expr)

    body = [f"    {s} = {text(d)}" for s, d in outside]
    for name, column_seeds, column in spec.columns:
        if not column_seeds:             # a plain vector beside the loops (dynamics' rhs)
            printed += [f"    {name}[{i}] = {text(se.sympify(e)) if e != 0 else '0.0'}" for i, e in enumerate(column)]
            continue
        inside = [(s, d) for s, d in graph.used_nodes(column) if graph.inputs_of(s) & seeds]
        printed.append(f"    for k in range({len(column_seeds)}):")
        printed += [f"        {s} = 1.0 if k == {i} else 0.0" for i, s in enumerate(column_seeds)]
        printed += [f"        {s} = {text(d)}" for s, d in inside]
        printed += [f"        {name}[{i}, k] = {text(se.sympify(e)) if e != 0 else '0.0'}" for i, e in enumerate(column)]
    args = ", ".join(spec.signature)
    lines = ['@njit(**KERNEL_OPTIONS)', f"def {spec.name}({args}):",
             f'    """{spec.doc}."""']
    lines += _load_lines(used, inputs.loads(spec.args)) + body + printed
    lines += [f"    {line}" for line in spec.epilogue]
    n_entries = sum(len(column) * max(1, len(column_seeds)) for _, column_seeds, column in spec.columns)
    return KernelText(spec.name, [], "\n".join(lines), n_entries=n_entries, n_temps=len(body))


def _placeholder_map(inputs):
    """expr -> expr with the model's input symbols renamed to their placeholders (q_0, p_1, t)."""
    rename = {se.Symbol(s.name): se.Symbol(new) for s, new in inputs.rename.items()}

    def placeholders(expr):
        used = {s: rename[s] for s in expr.free_symbols if s in rename}
        return expr.xreplace(used) if used else expr
    return placeholders


def graph_body(inputs, exprs):
    """(nodes, reduced) for a model derived through an expression graph (derive/graph.py):
    nodes [(name, symengine definition over placeholders)] that ``exprs`` use, in evaluation
    order, and ``exprs`` over placeholders. No CSE: every node is already a short expression
    shared by name, and the outputs are nodes or short sums of node products."""
    placeholders = _placeholder_map(inputs)
    nodes = [(str(sym), placeholders(d)) for sym, d in inputs.graph.used_nodes(exprs)]
    return nodes, [placeholders(se.sympify(e)) for e in exprs]


def _doc(spec, zeros, entries):
    doc = f"{spec.doc}."
    if zeros:
        doc += (f"\n    Structurally zero (written as 0.0, not computed): {len(zeros)} of "
                f"{len(entries)} entries.\n    ")
    return doc
