"""A generated kernel as LLVM IR: the Python subset the generator writes, lowered without numba.

numba spends most of a kernel's compile in its front end (typing and lowering each operation,
about a millisecond per operation of a big kernel); LLVM itself compiles the same straight-line
code in a small fraction of that. This module reads a kernel's Python source (the generated
text, which is straight-line arithmetic with a few loops) and writes LLVM IR for it directly;
jit/native.py compiles that IR with llvmlite and hands its address to the portable glue as a
numba first-class function.

The subset (what the generated kernels and the linear algebra they call use):
- values: float64, int64, bool; arrays: 1-D and C-contiguous 2-D float64 (data pointer and
  shape), a row of a 2-D array (``W[0]``), ``a.reshape(k)`` of a contiguous array, ``a.shape[i]``;
- statements: assignment (chained ``a[i] = b[j] = x``, tuple unpacking), augmented assignment,
  ``if``/``else``, ``for`` over ``range(...)`` or over a tuple of arrays (unrolled), ``return``,
  calls of other functions of the subset (a sibling kernel, ``cholesky_inplace``), a docstring;
- expressions: + - * / ** (integer exponents by repeated squaring, as numba does), unary -,
  comparisons, ``and``/``or``/``not``, ``x if c else y``, ``abs``, ``max``, ``min``, ``float``,
  ``math.*`` functions and constants, module constants (int, float, bool).
Anything else raises Unsupported naming the construct and line: the caller then compiles that
kernel with numba (one line says so), never a different answer.

The exported function of a kernel has numba's C-wrapper ABI for the portable argument types
(jit.portable._kernel_arg_types): each array is numba's array structure passed by value, t a
double; it returns what numba's type inference gives (float64, int64, bool, or none as a null
``i8*``). That ABI is read from numba's target context (array_struct_types), the one place that
depends on numba's data model.
"""

from __future__ import annotations

import ast
import inspect
import math
import textwrap

from llvmlite import ir

F64 = ir.DoubleType()
I64 = ir.IntType(64)
I1 = ir.IntType(1)
I8P = ir.IntType(8).as_pointer()
F64P = F64.as_pointer()

#: math functions lowered to LLVM intrinsics (the same libm routines numba calls for them).
_INTRINSICS = {"sin": "llvm.sin.f64", "cos": "llvm.cos.f64", "exp": "llvm.exp.f64",
               "log": "llvm.log.f64", "sqrt": "llvm.sqrt.f64", "fabs": "llvm.fabs.f64",
               "floor": "llvm.floor.f64", "ceil": "llvm.ceil.f64", "log10": "llvm.log10.f64",
               "log2": "llvm.log2.f64", "trunc": "llvm.trunc.f64"}
#: math functions of one or two doubles called from the C library by name.
_LIBM_1 = ("tan", "asin", "acos", "atan", "sinh", "cosh", "tanh", "asinh", "acosh", "atanh",
           "expm1", "log1p", "erf", "erfc", "gamma", "lgamma", "cbrt")
_LIBM_2 = ("atan2", "hypot", "copysign", "fmod", "pow")
_LIBM_NAMES = {"gamma": "tgamma"}
_MATH_CONSTANTS = {"pi": math.pi, "e": math.e, "tau": math.tau, "inf": math.inf,
                   "nan": math.nan}

#: The C library functions a module may call (jit/native.py resolves their addresses).
LIBM_SYMBOLS = tuple(sorted({_LIBM_NAMES.get(n, n) for n in _LIBM_1 + _LIBM_2}))


class Unsupported(Exception):
    """A construct outside the subset: the kernel is compiled by numba instead."""


class Array:
    """An array value: its data pointer and its shape (LLVM i64 values), C-contiguous."""

    def __init__(self, data, shape):
        self.data, self.shape = data, tuple(shape)

    @property
    def ndim(self):
        return len(self.shape)


class ArrayTuple:
    """A tuple of arrays (``for J in (Jq, Jqd)``): only iterated, at translation time."""

    def __init__(self, items):
        self.items = items


def _numba_array_struct(ndim):
    """numba's value type of a C-contiguous float64 array of ``ndim`` dimensions."""
    from numba import types
    from numba.core.registry import cpu_target
    ty = types.Array(types.float64, ndim, "C")
    return cpu_target.target_context.get_value_type(ty)


_STRUCTS = {}


def array_struct_types(ndim):
    """(llvmlite type of numba's array structure, index of its data pointer, index of its
    shape array) for ``ndim`` dimensions; the layout is checked, not assumed."""
    if ndim not in _STRUCTS:
        numba_ty = _numba_array_struct(ndim)
        text = str(numba_ty)
        expected = f"{{i8*, i8*, i64, i64, double*, [{ndim} x i64], [{ndim} x i64]}}"
        if text.replace("ptr", "i8*") != expected and text != expected:
            raise Unsupported(f"numba's array structure is {text}, not {expected}")
        elems = [I8P, I8P, I64, I64, F64P, ir.ArrayType(I64, ndim), ir.ArrayType(I64, ndim)]
        _STRUCTS[ndim] = (ir.LiteralStructType(elems), 4, 5)
    return _STRUCTS[ndim]


_PARSED: dict = {}


def function_source(fn):
    """(source text, ast.FunctionDef, globals) of a Python function or a numba dispatcher,
    parsed once per function object."""
    py = getattr(fn, "py_func", fn)
    entry = _PARSED.get(id(py))
    if entry is not None and entry[0] is py:
        return entry[1]
    source = _top_level_source(py)
    node = _parsed_function(source, py)
    if node is None:
        try:
            source = textwrap.dedent(inspect.getsource(py))
        except (OSError, TypeError) as exc:
            raise Unsupported(f"no source for {getattr(py, '__name__', py)!r}: {exc}") from None
        node = ast.parse(source).body[0]
    if not isinstance(node, ast.FunctionDef):
        raise Unsupported(f"{py.__name__} is not a plain function")
    _PARSED[id(py)] = (py, (source, node, py.__globals__))
    return source, node, py.__globals__


def _top_level_source(py):
    """The text of a top-level function of a generated module, from its first line (decorator)
    to the next line that starts in column 0: inspect.getsource finds the same end by
    tokenizing the whole function, most of the time a big kernel's parse took. None for a
    function of any other file (inspect reads it)."""
    globs = getattr(py, "__globals__", {})
    code = getattr(py, "__code__", None)
    if code is None or "TEXT_SHA" not in globs or "check_current" not in globs \
            or "." in py.__qualname__:
        return None
    import linecache
    lines = linecache.getlines(code.co_filename, globs)
    start = code.co_firstlineno - 1
    if not 0 <= start < len(lines):
        return None
    first = start
    while first < len(lines) and lines[first].startswith("@"):      # its decorators
        first += 1
    if first >= len(lines) or not lines[first].startswith("def "):
        return None
    end = first + 1
    while end < len(lines) and (lines[end][:1] in (" ", "\t", "#") or not lines[end].strip()):
        end += 1
    return "".join(lines[start:end])


def _parsed_function(source, py):
    """The FunctionDef of ``py`` parsed from ``source``, or None when the text is not that
    function alone (then inspect reads it)."""
    if source is None:
        return None
    try:
        body = ast.parse(source).body
    except SyntaxError:
        return None
    if len(body) != 1 or not isinstance(body[0], ast.FunctionDef) or body[0].name != py.__name__:
        return None
    return body[0]


def parse_function(fn):
    """(ast.FunctionDef, globals) of a Python function or a numba dispatcher."""
    _, node, globs = function_source(fn)
    return node, globs


class ModuleBuilder:
    """One LLVM module: the exported kernel and every function of the subset it calls.

    ``arg_kinds`` of the exported kernel: "t" (a double) or an array of 1 or 2 dimensions, as
    the portable glue passes them (jit.portable._kernel_arg_types)."""

    def __init__(self, name):
        self.module = ir.Module(name=name)
        self.functions = {}       # (py function id, arg signature) -> (ir.Function, restype)
        self._declared = {}

    # -- declarations -------------------------------------------------------------------------
    def constant_array(self, key, values, element):
        """A module-level constant array (a global numpy array the kernel reads, frozen as numba
        freezes it): the ir.GlobalVariable, made once per ``key``."""
        if key not in self._declared:
            flat = [float(v) if element is F64 else int(v) for v in values]
            ty = ir.ArrayType(element, len(flat))
            var = ir.GlobalVariable(self.module, ty, name=f"const_{len(self._declared)}")
            var.global_constant = True
            var.linkage = "internal"
            var.initializer = ir.Constant(ty, flat)
            self._declared[key] = var
        return self._declared[key]

    def intrinsic(self, name, nargs=1):
        if name not in self._declared:
            fnty = ir.FunctionType(F64, [F64] * nargs)
            self._declared[name] = ir.Function(self.module, fnty, name=name)
        return self._declared[name]

    # -- functions ---------------------------------------------------------------------------
    def internal(self, fn, arg_sig):
        """The internal function of Python function ``fn`` for argument kinds ``arg_sig`` (a
        tuple: "f" double, "i" int, "b" bool, ("a", ndim) an array as a data pointer and
        ndim shape values). Returns (ir.Function, return kind)."""
        py = getattr(fn, "py_func", fn)
        key = (id(py), arg_sig)
        if key in self.functions:
            entry = self.functions[key]
            if entry is None:
                raise Unsupported(f"{py.__name__} calls itself")
            return entry
        self.functions[key] = None
        node, globs = parse_function(py)
        entry = FunctionLowering(self, node, globs, arg_sig, f"{py.__name__}_{len(self.functions)}").lower()
        self.functions[key] = entry
        return entry

    def export(self, fn, export_name, arg_kinds):
        """The kernel ``fn`` with numba's C-wrapper ABI under ``export_name``; returns its
        return kind ("f", "i", "b" or None)."""
        arg_sig, ll_args = [], []
        for kind in arg_kinds:
            if kind == "t":
                arg_sig.append("f")
                ll_args.append(F64)
            else:
                arg_sig.append(("a", kind))
                ll_args.append(array_struct_types(kind)[0])
        inner, ret = self.internal(fn, tuple(arg_sig))
        ret_ty = {"f": F64, "i": I64, "b": I1, None: I8P}[ret]
        wrapper = ir.Function(self.module, ir.FunctionType(ret_ty, ll_args), name=export_name)
        builder = ir.IRBuilder(wrapper.append_basic_block("entry"))
        call_args = []
        for kind, value in zip(arg_kinds, wrapper.args):
            if kind == "t":
                call_args.append(value)
                continue
            _, data_at, shape_at = array_struct_types(kind)
            call_args.append(builder.extract_value(value, data_at))
            shape = builder.extract_value(value, shape_at)
            call_args.extend(builder.extract_value(shape, d) for d in range(kind))
        result = builder.call(inner, call_args)
        builder.ret(ir.Constant(I8P, None) if ret is None else result)
        return ret


def _arg_types(arg_sig):
    out = []
    for kind in arg_sig:
        if kind == "f":
            out.append(F64)
        elif kind == "i":
            out.append(I64)
        elif kind == "b":
            out.append(I1)
        else:
            out.append(F64P)
            out.extend([I64] * kind[1])
    return out


class _Returned(Exception):
    pass


class FunctionLowering:
    """Lowers one ast.FunctionDef of the subset into an internal LLVM function."""

    def __init__(self, owner, node, globs, arg_sig, name):
        self.owner, self.node, self.globs, self.arg_sig = owner, node, globs, arg_sig
        self.name = name
        self.vars = {}          # name -> (kind, alloca) for scalars, or Array / ArrayTuple
        self.ret_kind = None
        self.declared = {}
        self.single = frozenset()
        self.frame, self.frame_slots = None, {}
        self.loops = []          # _Loop of each loop being lowered, outermost first
        self._reads = {}         # id(statement) -> (statement, the names it reads)

    def fail(self, node, what):
        line = getattr(node, "lineno", "?")
        raise Unsupported(f"{self.node.name}, line {line} of its source: {what}")

    # -- the function ---------------------------------------------------------------------
    def lower(self):
        kinds = _KindPass(self)
        ret_kind = kinds.kind()
        self.declared = kinds.env
        self.single = _single_assignments(self.node)
        ret_ty = {"f": F64, "i": I64, "b": I1, None: ir.VoidType()}[ret_kind]
        fnty = ir.FunctionType(ret_ty, _arg_types(self.arg_sig))
        fn = ir.Function(self.owner.module, fnty, name=self.name)
        fn.linkage = "internal"
        self.fn = fn
        self.ret_kind = ret_kind
        self.entry = fn.append_basic_block("entry")
        body = fn.append_basic_block("body")
        self.b = ir.IRBuilder(body)
        params = [a.arg for a in self.node.args.args]
        if self.node.args.vararg or self.node.args.kwonlyargs or self.node.args.kwarg:
            self.fail(self.node, "variable or keyword-only arguments")
        if len(params) != len(self.arg_sig):
            self.fail(self.node, f"{len(params)} parameters, called with {len(self.arg_sig)}")
        args = iter(fn.args)
        for name, kind in zip(params, self.arg_sig):
            if isinstance(kind, tuple):
                data = next(args)
                shape = [next(args) for _ in range(kind[1])]
                self.vars[name] = Array(data, shape)
            else:
                self._store_scalar(name, kind, next(args))
        self._statements(self.node.body, CHUNK_STATEMENTS)
        if self.frame is not None:       # its size is known once every piece is lowered
            self.frame.operands = [ir.Constant(I64, max(1, len(self.frame_slots)))]
        if not self.b.block.is_terminated:
            if ret_kind is not None:
                self.fail(self.node, "a path ends without returning a value")
            self.b.ret_void()
        ir.IRBuilder(self.entry).branch(body)
        return fn, ret_kind

    # -- long straight-line runs as functions of their own ---------------------------------
    def _statements(self, stmts, chunk):
        """Lower a block like _block, with its runs of at least ``chunk`` plain assignments
        lowered as separate functions ("pieces") of at most CHUNK_STATEMENTS each: LLVM's
        register allocator and optimizer take time that grows faster than linearly with the
        values live at once in one function, and a kernel of a 30-body robot holds tens of
        thousands of statements (a Jacobian's column loop, thousands per iteration, with the
        primal values live across it). The values a piece reads from before it and the ones it
        defines for later statements pass through a frame of doubles on the kernel's stack; an
        input that does not change in a loop is stored there once, before the loop."""
        # the last statement reading each name: a name is read at or after statement i when
        # its last read is (a set of the later reads per statement would be quadratic)
        last_read = {}
        for i, stmt in enumerate(stmts):
            for name in self._names_read(stmt):
                last_read[name] = i

        def read_from(i):
            return lambda name: last_read.get(name, -1) >= i
        run = []
        for i, stmt in enumerate(stmts):
            if self.b.block.is_terminated:
                return
            if _plain_assignment(stmt):
                run.append(stmt)
                if len(run) == CHUNK_STATEMENTS:
                    self._run(run, read_from(i + 1), chunk)
                    run = []
                continue
            if run:
                self._run(run, read_from(i), chunk)
                run = []
            self._stmt(stmt)
        if run and not self.b.block.is_terminated:
            self._run(run, read_from(len(stmts)), chunk)

    def _names_read(self, stmt):
        """_names_read(stmt), once per statement: _statements and _run both ask."""
        entry = self._reads.get(id(stmt))
        if entry is None or entry[0] is not stmt:
            entry = self._reads[id(stmt)] = (stmt, _names_read(stmt))
        return entry[1]

    def _run(self, stmts, read_after, chunk):
        """Lower ``stmts`` (plain assignments) here, or as one piece when there are at least
        ``chunk`` of them and every value crossing its boundary is a float. read_after(name):
        whether a statement after them reads the name."""
        if len(stmts) < chunk:
            self._block(stmts)
            return
        assigned = set()
        for stmt in stmts:
            for t in stmt.targets:
                if isinstance(t, ast.Name):
                    assigned.add(t.id)
        read = set().union(*(self._names_read(s) for s in stmts))
        scalars = {n for n, v in self.vars.items() if isinstance(v, tuple)}
        inputs = sorted(read & scalars)
        outputs = sorted(n for n in assigned if read_after(n))
        crossing = inputs + [n for n in outputs if n not in inputs]
        arrays = [(n, v) for n, v in self.vars.items() if isinstance(v, Array)]
        if any(self.vars[n][0] != "f" for n in inputs) or any(
                self.declared.get(n) not in ("f", None) for n in outputs):
            self._block(stmts)
            return
        for name in crossing:
            self.frame_slots.setdefault(name, len(self.frame_slots))
        if self.frame is None:
            self.frame = ir.IRBuilder(self.entry).alloca(F64, size=ir.Constant(I64, 1),
                                                         name="frame")
        for name in inputs:
            self._store_input(name)
        piece = _PieceLowering(self, stmts, inputs, outputs, arrays)
        fn = piece.lower()
        args = [self.frame]
        for _, array in arrays:
            args.append(array.data)
            args.extend(array.shape)
        self.b.call(fn, args)
        for name in outputs:
            self._store_scalar(name, "f", self.b.load(self._slot(self.frame, name)))

    def _store_input(self, name):
        """Store a piece's input into its frame slot: once, before the outermost loop in which
        it does not change, or here."""
        for loop in self.loops:
            if name in loop.before and name not in loop.assigned:
                if name not in loop.stored:
                    loop.stored.add(name)
                    builder = ir.IRBuilder(loop.preheader)
                    builder.position_before(loop.preheader.terminator)
                    saved, self.b = self.b, builder
                    try:
                        kind, value = self._e_Name(ast.Name(id=name, ctx=ast.Load()))
                        self.b.store(value, self._slot(self.frame, name))
                    finally:
                        self.b = saved
                return
        kind, value = self._e_Name(ast.Name(id=name, ctx=ast.Load()))
        self.b.store(value, self._slot(self.frame, name))

    def _slot(self, frame, name):
        return self.b.gep(frame, [ir.Constant(I64, self.frame_slots[name])])

    # -- variables ------------------------------------------------------------------------
    def _alloca(self, ty, name):
        builder = ir.IRBuilder(self.entry)
        return builder.alloca(ty, name=name)

    def _store_scalar(self, name, kind, value):
        if name in self.single:
            # assigned once, in the function's top-level block: the value itself (an SSA
            # value dominates every later statement), no stack slot to load and store
            declared = self.declared.get(name)
            if declared in ("f", "i", "b") and _unify(declared, kind) == declared:
                value, kind = self.cast(value, kind, declared), declared
            self.vars[name] = (kind, None, value)
            return
        entry = self.vars.get(name)
        if entry is None or not isinstance(entry, tuple):
            if isinstance(entry, (Array, ArrayTuple)):
                raise Unsupported(f"{self.node.name}: {name} is both an array and a scalar")
            declared = self.declared.get(name)
            if declared in ("f", "i", "b") and _unify(declared, kind) == declared:
                kind_of_slot = declared        # an integer name later assigned a float
            else:
                kind_of_slot = kind
            slot = self._alloca({"f": F64, "i": I64, "b": I1}[kind_of_slot], name)
            self.vars[name] = (kind_of_slot, slot)
            entry = self.vars[name]
        have, slot = entry
        value = self.cast(value, kind, have)
        self.b.store(value, slot)

    def cast(self, value, kind, to):
        if kind == to:
            return value
        if to == "f" and kind == "i":
            return self.b.sitofp(value, F64)
        if to == "f" and kind == "b":
            return self.b.uitofp(value, F64)
        if to == "i" and kind == "b":
            return self.b.zext(value, I64)
        raise Unsupported(f"{self.node.name}: a {_KIND_NAMES[kind]} stored where a "
                          f"{_KIND_NAMES[to]} was")

    # -- statements -----------------------------------------------------------------------
    def _block(self, stmts):
        for stmt in stmts:
            if self.b.block.is_terminated:
                return              # code after a return: unreachable
            self._stmt(stmt)

    def _stmt(self, node):
        if isinstance(node, ast.Expr):
            if isinstance(node.value, ast.Constant) and isinstance(node.value.value, str):
                return
            if isinstance(node.value, ast.Call):
                self._call(node.value, statement=True)
                return
            self.fail(node, "an expression statement")
        elif isinstance(node, ast.Assign):
            value = self.expr(node.value)
            for target in node.targets:
                self._assign(target, value, node)
        elif isinstance(node, ast.AugAssign):
            current = self.expr(_load(node.target))
            value = self._binop(node.op, current, self.expr(node.value), node)
            self._assign(node.target, value, node)
        elif isinstance(node, ast.If):
            self._if(node)
        elif isinstance(node, ast.For):
            self._for(node)
        elif isinstance(node, ast.Return):
            self._return(node)
        elif isinstance(node, ast.Pass):
            return
        else:
            self.fail(node, f"statement {type(node).__name__}")

    def _assign(self, target, value, node):
        if isinstance(target, ast.Name):
            if isinstance(value, (Array, ArrayTuple)):
                if target.id in self.vars and not isinstance(self.vars[target.id], type(value)):
                    self.fail(node, f"{target.id} rebound to another kind of value")
                self.vars[target.id] = value
            else:
                kind, v = value
                self._store_scalar(target.id, kind, v)
        elif isinstance(target, ast.Subscript):
            array = self.expr(target.value)
            if not isinstance(array, Array):
                self.fail(node, "assignment into something that is not an array")
            if isinstance(value, (Array, ArrayTuple)):
                self.fail(node, "an array stored into an array element")
            ptr = self._element(array, target.slice, node)
            self.b.store(self.cast(value[1], value[0], "f"), ptr)
        elif isinstance(target, ast.Tuple):
            if not isinstance(value, tuple) or value[0] != "tuple":
                self.fail(node, "tuple unpacking of a value that is not a tuple")
            items = value[1]
            if len(items) != len(target.elts):
                self.fail(node, "tuple unpacking of the wrong length")
            for t, v in zip(target.elts, items):
                self._assign(t, v, node)
        else:
            self.fail(node, f"assignment to {type(target).__name__}")

    def _if(self, node):
        cond = self.truth(self.expr(node.test), node)
        then = self.fn.append_basic_block("then")
        other = self.fn.append_basic_block("else")
        after = self.fn.append_basic_block("endif")
        self.b.cbranch(cond, then, other)
        reached = False
        for block, body in ((then, node.body), (other, node.orelse)):
            self.b.position_at_end(block)
            self._block(body)
            if not self.b.block.is_terminated:
                self.b.branch(after)
                reached = True
        self.b.position_at_end(after)
        if not reached:
            self.b.unreachable()        # both branches returned: what follows is dead

    def _for(self, node):
        if node.orelse:
            self.fail(node, "for ... else")
        if not isinstance(node.target, ast.Name):
            self.fail(node, "a loop target that is not a name")
        it = node.iter
        if isinstance(it, ast.Tuple):
            for elt in it.elts:
                self._assign(node.target, self.expr(elt), node)
                self._block(node.body)
                if self.b.block.is_terminated:
                    return
            return
        if not (isinstance(it, ast.Name) and it.id not in self.vars
                and _int_array(self.globs.get(it.id)) is not None) and not (
                isinstance(it, ast.Call) and isinstance(it.func, ast.Name)
                and it.func.id == "range" and 1 <= len(it.args) <= 3 and not it.keywords):
            self.fail(node, "a loop over something other than range(...) or a tuple")
        indices = _int_array(self.globs.get(it.id)) if isinstance(it, ast.Name) \
            and it.id not in self.vars else None
        if indices is not None:
            self._for_constant(node, indices)
            return
        bounds = [self.expr(a) for a in it.args]
        for b in bounds:
            if not isinstance(b, tuple) or b[0] != "i":
                self.fail(node, "range() of a value that is not an integer")
        start = ir.Constant(I64, 0) if len(bounds) == 1 else bounds[0][1]
        stop = bounds[0][1] if len(bounds) == 1 else bounds[1][1]
        step_value = 1
        if len(bounds) == 3:
            step_node = it.args[2]
            if not (isinstance(step_node, ast.Constant) and isinstance(step_node.value, int)) and not (
                    isinstance(step_node, ast.UnaryOp) and isinstance(step_node.op, ast.USub)
                    and isinstance(step_node.operand, ast.Constant)):
                self.fail(node, "range() with a step that is not a literal")
            step_value = ast.literal_eval(step_node)
            if step_value == 0:
                self.fail(node, "range() with step 0")
        counter = self._alloca(I64, f"{node.target.id}_next")
        self.b.store(start, counter)
        head = self.fn.append_basic_block("loop")
        body = self.fn.append_basic_block("loop_body")
        after = self.fn.append_basic_block("loop_end")
        preheader = self.b.block
        self.b.branch(head)
        self.b.position_at_end(head)
        index = self.b.load(counter)
        more = self.b.icmp_signed("<" if step_value > 0 else ">", index, stop)
        self.b.cbranch(more, body, after)
        self.b.position_at_end(body)
        self._store_scalar(node.target.id, "i", index)
        self.b.store(self.b.add(index, ir.Constant(I64, step_value)), counter)
        self._loop_body(node, preheader)
        if not self.b.block.is_terminated:
            self.b.branch(head)
        self.b.position_at_end(after)

    def _loop_body(self, node, preheader):
        """The body of a loop whose entry branch ends ``preheader``: its long runs as pieces
        (_statements), their loop-invariant inputs stored in the preheader."""
        before = {n for n, v in self.vars.items() if isinstance(v, tuple)}
        assigned = {t.id for sub in node.body for t in _walk(sub)
                    if type(t) is ast.Name and type(t.ctx) is ast.Store}
        assigned.add(node.target.id)
        self.loops.append(_Loop(preheader, before, assigned))
        try:
            self._statements(node.body, LOOP_CHUNK_STATEMENTS)
        finally:
            self.loops.pop()

    def _for_constant(self, node, values):
        """``for k in INDICES``: a loop over a module constant int64 array."""
        if values.size == 0:
            return
        var = self.owner.constant_array(("i", id(values)), values, I64)
        counter = self._alloca(I64, f"{node.target.id}_at")
        self.b.store(ir.Constant(I64, 0), counter)
        head = self.fn.append_basic_block("cloop")
        body = self.fn.append_basic_block("cloop_body")
        after = self.fn.append_basic_block("cloop_end")
        preheader = self.b.block
        self.b.branch(head)
        self.b.position_at_end(head)
        at = self.b.load(counter)
        self.b.cbranch(self.b.icmp_signed("<", at, ir.Constant(I64, values.size)), body, after)
        self.b.position_at_end(body)
        value = self.b.load(self.b.gep(var, [ir.Constant(I64, 0), at]))
        self._store_scalar(node.target.id, "i", value)
        self.b.store(self.b.add(at, ir.Constant(I64, 1)), counter)
        self._loop_body(node, preheader)
        if not self.b.block.is_terminated:
            self.b.branch(head)
        self.b.position_at_end(after)

    def _return(self, node):
        if _returns_nothing(node):
            if self.ret_kind is not None:
                self.fail(node, "a bare return in a function that returns a value")
            self.b.ret_void()
            return
        value = self.expr(node.value)
        if not isinstance(value, tuple) or value[0] not in ("f", "i", "b"):
            self.fail(node, "a return of something that is not a number")
        self.b.ret(self.cast(value[1], value[0], self.ret_kind))

    # -- expressions: each gives (kind, llvm value), an Array, an ArrayTuple or
    # ("tuple", [values]) -------------------------------------------------------------------
    def expr(self, node):
        method = getattr(self, f"_e_{type(node).__name__}", None)
        if method is None:
            self.fail(node, f"expression {type(node).__name__}")
        return method(node)

    def scalar(self, node):
        value = self.expr(node)
        if not isinstance(value, tuple) or value[0] not in ("f", "i", "b"):
            self.fail(node, "an array where a number is needed")
        return value

    def truth(self, value, node):
        if not isinstance(value, tuple) or value[0] not in ("f", "i", "b"):
            self.fail(node, "the truth of something that is not a number")
        kind, v = value
        if kind == "b":
            return v
        if kind == "i":
            return self.b.icmp_signed("!=", v, ir.Constant(I64, 0))
        return self.b.fcmp_unordered("!=", v, ir.Constant(F64, 0.0))

    def _constant(self, value, node):
        if isinstance(value, bool):
            return "b", ir.Constant(I1, int(value))
        if isinstance(value, int):
            if not -2**63 <= value < 2**63:
                self.fail(node, f"the integer {value} does not fit in 64 bits")
            return "i", ir.Constant(I64, value)
        if isinstance(value, float):
            return "f", ir.Constant(F64, value)
        self.fail(node, f"the constant {value!r}")

    def _e_Constant(self, node):
        return self._constant(node.value, node)

    def _e_Name(self, node):
        name = node.id
        if name in self.vars:
            entry = self.vars[name]
            if isinstance(entry, tuple):
                if len(entry) == 3:
                    return entry[0], entry[2]
                kind, slot = entry
                return kind, self.b.load(slot)
            return entry
        if name in ("True", "False"):
            return self._constant(name == "True", node)
        if name in self.globs:
            value = self.globs[name]
            if isinstance(value, (bool, int, float)):
                return self._constant(value, node)
            array = _float_array(value)
            if array is not None and array.ndim in (1, 2) and array.size:
                var = self.owner.constant_array(("f", id(value)), array.ravel(), F64)
                data = self.b.gep(var, [ir.Constant(I64, 0), ir.Constant(I64, 0)])
                return Array(data, [ir.Constant(I64, d) for d in array.shape])
        self.fail(node, f"the name {name!r}")

    def _e_Attribute(self, node):
        if isinstance(node.value, ast.Name) and self.globs.get(node.value.id) is math:
            if node.attr in _MATH_CONSTANTS:
                return "f", ir.Constant(F64, _MATH_CONSTANTS[node.attr])
        if node.attr == "shape":
            array = self.expr(node.value)
            if isinstance(array, Array):
                return "tuple", [("i", s) for s in array.shape]
        self.fail(node, f"the attribute {ast.unparse(node)}")

    def _e_Tuple(self, node):
        items = [self.expr(e) for e in node.elts]
        if items and all(isinstance(i, Array) for i in items):
            return ArrayTuple(items)
        return "tuple", items

    def _e_Subscript(self, node):
        base = self.expr(node.value)
        if isinstance(base, tuple) and base[0] == "tuple":
            index = node.slice
            if isinstance(index, ast.Constant) and isinstance(index.value, int):
                try:
                    return base[1][index.value]
                except IndexError:
                    self.fail(node, "a tuple index out of range")
            self.fail(node, "a tuple indexed by something other than a literal")
        if not isinstance(base, Array):
            self.fail(node, "indexing something that is not an array")
        indices = node.slice.elts if isinstance(node.slice, ast.Tuple) else [node.slice]
        if base.ndim == 2 and len(indices) == 1:
            row = self.scalar(indices[0])
            if row[0] != "i":
                self.fail(node, "an array index that is not an integer")
            offset = self.b.mul(self._wrap(row[1], base.shape[0]), base.shape[1])
            return Array(self.b.gep(base.data, [offset]), base.shape[1:])
        return "f", self.b.load(self._element(base, node.slice, node))

    def _wrap(self, index, size):
        """A negative index counts from the end, as in numba (no bounds check, as the kernels
        are compiled without)."""
        if isinstance(index, ir.Constant) and index.constant >= 0:
            return index
        negative = self.b.icmp_signed("<", index, ir.Constant(I64, 0))
        return self.b.select(negative, self.b.add(index, size), index)

    def _element(self, array, slice_node, node):
        indices = slice_node.elts if isinstance(slice_node, ast.Tuple) else [slice_node]
        if len(indices) != array.ndim:
            self.fail(node, f"{len(indices)} indices into an array of {array.ndim} dimensions")
        values = []
        for idx in indices:
            kind, v = self.scalar(idx)
            if kind != "i":
                self.fail(node, "an array index that is not an integer")
            values.append(v)
        offset = self._wrap(values[0], array.shape[0])
        for d in range(1, array.ndim):
            offset = self.b.add(self.b.mul(offset, array.shape[d]),
                                self._wrap(values[d], array.shape[d]))
        return self.b.gep(array.data, [offset])

    def _e_UnaryOp(self, node):
        if isinstance(node.op, ast.Not):
            return "b", self.b.not_(self.truth(self.expr(node.operand), node))
        kind, v = self.scalar(node.operand)
        if isinstance(node.op, ast.USub):
            if kind == "f":
                return "f", self.b.fneg(v)
            if kind == "b":
                kind, v = "i", self.b.zext(v, I64)
            return "i", self.b.neg(v)
        if isinstance(node.op, ast.UAdd):
            return kind, v
        self.fail(node, f"the operator {type(node.op).__name__}")

    def _e_BinOp(self, node):
        return self._binop(node.op, self.scalar(node.left), self.scalar(node.right), node,
                           right_node=node.right)

    def _binop(self, op, left, right, node, right_node=None):
        (lk, lv), (rk, rv) = left, right
        if isinstance(op, ast.Pow):
            return self._pow(left, right, node, right_node)
        if isinstance(op, ast.Div) or "f" in (lk, rk):
            lv, rv = self.cast(lv, lk, "f"), self.cast(rv, rk, "f")
            if isinstance(op, ast.Mod):
                return "f", self._float_mod(lv, rv)
            ops = {ast.Add: self.b.fadd, ast.Sub: self.b.fsub, ast.Mult: self.b.fmul,
                   ast.Div: self.b.fdiv}
            if type(op) not in ops:
                self.fail(node, f"the operator {type(op).__name__} on floats")
            return "f", ops[type(op)](lv, rv)
        lv, rv = self.cast(lv, lk, "i"), self.cast(rv, rk, "i")
        ops = {ast.Add: self.b.add, ast.Sub: self.b.sub, ast.Mult: self.b.mul}
        if type(op) not in ops:
            self.fail(node, f"the operator {type(op).__name__} on integers")
        return "i", ops[type(op)](lv, rv)

    def _float_mod(self, a, b):
        """Python's a % b on floats: the remainder takes the sign of b (C's fmod, then b added
        when the signs differ), as numba computes it."""
        r = self.b.frem(a, b)
        zero = ir.Constant(F64, 0.0)
        nonzero = self.b.fcmp_ordered("!=", r, zero)
        differ = self.b.xor(self.b.fcmp_ordered("<", r, zero), self.b.fcmp_ordered("<", b, zero))
        adjusted = self.b.select(self.b.and_(nonzero, differ), self.b.fadd(r, b), r)
        # a zero remainder takes b's sign too (copysign), as in Python
        return self.b.select(nonzero, adjusted,
                             self.b.call(self.owner.intrinsic("llvm.copysign.f64", 2), [zero, b]))

    def _pow(self, left, right, node, right_node):
        (lk, lv), (rk, rv) = left, right
        exponent = None
        if right_node is not None:
            try:
                exponent = ast.literal_eval(right_node)
            except ValueError:
                exponent = None
        if lk == "i" and rk == "i":
            self.fail(node, "an integer power")
        base = self.cast(lv, lk, "f")
        if isinstance(exponent, int) and not isinstance(exponent, bool) and abs(exponent) <= 64:
            # numba's float ** int: repeated squaring, the reciprocal for a negative exponent
            result, square, k = ir.Constant(F64, 1.0), base, abs(exponent)
            first = True
            while k:
                if k & 1:
                    result = square if first else self.b.fmul(result, square)
                    first = False
                k >>= 1
                if k:
                    square = self.b.fmul(square, square)
            if exponent < 0:
                result = self.b.fdiv(ir.Constant(F64, 1.0), result)
            return "f", result
        return "f", self.b.call(self.owner.intrinsic("llvm.pow.f64", 2),
                                [base, self.cast(rv, rk, "f")])

    def _e_Compare(self, node):
        left = self.scalar(node.left)
        result = None
        for op, comparator in zip(node.ops, node.comparators):
            right = self.scalar(comparator)
            c = self._compare(op, left, right, node)
            result = c if result is None else self.b.and_(result, c)
            left = right
        return "b", result

    _FLOAT_CMP = {ast.Lt: "<", ast.LtE: "<=", ast.Gt: ">", ast.GtE: ">=", ast.Eq: "==",
                  ast.NotEq: "!="}

    def _compare(self, op, left, right, node):
        (lk, lv), (rk, rv) = left, right
        sym = self._FLOAT_CMP.get(type(op))
        if sym is None:
            self.fail(node, f"the comparison {type(op).__name__}")
        if "f" in (lk, rk):
            lv, rv = self.cast(lv, lk, "f"), self.cast(rv, rk, "f")
            # Python: every comparison with NaN is False but !=, which is True
            if sym == "!=":
                return self.b.fcmp_unordered(sym, lv, rv)
            return self.b.fcmp_ordered(sym, lv, rv)
        lv, rv = self.cast(lv, lk, "i"), self.cast(rv, rk, "i")
        return self.b.icmp_signed(sym, lv, rv)

    def _e_BoolOp(self, node):
        # operands are comparisons and flags without side effects: both sides are evaluated
        values = [self.truth(self.expr(v), node) for v in node.values]
        result = values[0]
        for v in values[1:]:
            result = self.b.and_(result, v) if isinstance(node.op, ast.And) else self.b.or_(result, v)
        return "b", result

    def _e_IfExp(self, node):
        cond = self.truth(self.expr(node.test), node)
        then = self.fn.append_basic_block("ifexp_then")
        other = self.fn.append_basic_block("ifexp_else")
        after = self.fn.append_basic_block("ifexp_end")
        self.b.cbranch(cond, then, other)
        self.b.position_at_end(then)
        tk, tv = self.scalar(node.body)
        then_end = self.b.block
        self.b.position_at_end(other)
        ok, ov = self.scalar(node.orelse)
        kind = "f" if "f" in (tk, ok) else "i" if "i" in (tk, ok) else "b"
        ov = self.cast(ov, ok, kind)
        other_end = self.b.block
        self.b.branch(after)
        self.b.position_at_end(then_end)
        tv = self.cast(tv, tk, kind)
        self.b.branch(after)
        self.b.position_at_end(after)
        phi = self.b.phi({"f": F64, "i": I64, "b": I1}[kind])
        phi.add_incoming(tv, then_end)
        phi.add_incoming(ov, other_end)
        return kind, phi

    def _e_Call(self, node):
        return self._call(node, statement=False)

    def _call(self, node, statement):
        if node.keywords:
            self.fail(node, "a call with keyword arguments")
        func = node.func
        if isinstance(func, ast.Attribute) and func.attr == "reshape":
            array = self.expr(func.value)
            if not isinstance(array, Array):
                self.fail(node, "reshape of something that is not an array")
            dims = [self.scalar(a) for a in node.args]
            if len(dims) == 1 and dims[0][0] == "tuple":
                dims = dims[0][1]
            if any(k != "i" for k, _ in dims):
                self.fail(node, "reshape to a size that is not an integer")
            return Array(array.data, [v for _, v in dims])
        if isinstance(func, ast.Attribute) and isinstance(func.value, ast.Name) \
                and self.globs.get(func.value.id) is math:
            return self._math(func.attr, node)
        if isinstance(func, ast.Name) and func.id not in self.vars:
            name = func.id
            if name in ("abs", "max", "min", "float", "int", "bool") and name not in self.globs:
                return self._builtin(name, node)
            target = self.globs.get(name)
            if target is not None and callable(target):
                return self._call_function(target, node, statement)
        self.fail(node, f"a call of {ast.unparse(func)}")

    def _call_function(self, target, node, statement):
        args, sig = [], []
        for a in node.args:
            value = self.expr(a)
            if isinstance(value, Array):
                sig.append(("a", value.ndim))
                args.append(value.data)
                args.extend(value.shape)
            elif isinstance(value, tuple) and value[0] in ("f", "i", "b"):
                sig.append(value[0])
                args.append(value[1])
            else:
                self.fail(node, "a call with an argument that is neither a number nor an array")
        fn, ret = self.owner.internal(target, tuple(sig))
        result = self.b.call(fn, args)
        if ret is None:
            return "none", None
        return ret, result

    def _math(self, name, node):
        args = [self.scalar(a) for a in node.args]
        if name in ("isfinite", "isnan", "isinf") and len(args) == 1:
            kind, v = args[0]
            if kind != "f":
                return "b", ir.Constant(I1, int(name == "isfinite"))
            if name == "isnan":
                return "b", self.b.fcmp_unordered("uno", v, v)
            mag = self.b.call(self.owner.intrinsic("llvm.fabs.f64"), [v])
            inf = ir.Constant(F64, math.inf)
            if name == "isinf":
                return "b", self.b.fcmp_ordered("==", mag, inf)
            return "b", self.b.fcmp_ordered("<", mag, inf)
        floats = [self.cast(v, k, "f") for k, v in args]
        if name in _INTRINSICS and len(floats) == 1:
            return "f", self.b.call(self.owner.intrinsic(_INTRINSICS[name]), floats)
        if name in _LIBM_1 and len(floats) == 1 or name in _LIBM_2 and len(floats) == 2:
            symbol = _LIBM_NAMES.get(name, name)
            if name == "pow":
                symbol = "llvm.pow.f64"
            return "f", self.b.call(self.owner.intrinsic(symbol, len(floats)), floats)
        self.fail(node, f"math.{name} with {len(args)} arguments")

    def _builtin(self, name, node):
        args = [self.scalar(a) for a in node.args]
        if name == "abs" and len(args) == 1:
            kind, v = args[0]
            if kind == "f":
                return "f", self.b.call(self.owner.intrinsic("llvm.fabs.f64"), [v])
            v = self.cast(v, kind, "i")
            negative = self.b.icmp_signed("<", v, ir.Constant(I64, 0))
            return "i", self.b.select(negative, self.b.neg(v), v)
        if name in ("max", "min") and len(args) >= 2:
            kind = "f" if any(k == "f" for k, _ in args) else "i"
            values = [self.cast(v, k, kind) for k, v in args]
            result = values[0]
            for v in values[1:]:
                # Python's max/min: keep the first unless the next compares greater (less)
                if kind == "f":
                    better = self.b.fcmp_ordered(">" if name == "max" else "<", v, result)
                else:
                    better = self.b.icmp_signed(">" if name == "max" else "<", v, result)
                result = self.b.select(better, v, result)
            return kind, result
        if name == "float" and len(args) == 1:
            return "f", self.cast(args[0][1], args[0][0], "f")
        self.fail(node, f"{name}() with {len(args)} arguments")


_KIND_NAMES = {"f": "float", "i": "integer", "b": "bool"}

#: Plain assignments lowered into one function (FunctionLowering._statements): LLVM compiles
#: pieces of this size in time about linear in their number, at the cost of a call and the
#: frame's loads and stores per piece.
CHUNK_STATEMENTS = 2000

#: Inside a loop, a run of plain assignments this long is a piece already: what would make the
#: register allocator slow is the values live across the loop, which a piece does not see.
LOOP_CHUNK_STATEMENTS = 200


class _Loop:
    """A loop being lowered: the block that enters it, the scalar names defined before it, the
    names its body assigns, and the piece inputs already stored in its preheader."""

    def __init__(self, preheader, before, assigned):
        self.preheader, self.before, self.assigned = preheader, before, assigned
        self.stored = set()

_PURE_BUILTINS = ("abs", "max", "min", "float")


#: Fields of AST nodes that never hold a node _walk needs: contexts, operators, names.
_LEAF_FIELDS = frozenset(("ctx", "op", "ops", "kind", "type_comment", "id", "arg", "attr",
                          "name", "module", "level", "is_async", "conversion"))
_CHILD_FIELDS: dict = {}


def _walk(node) -> list:
    """Every node under ``node`` (itself included) but the context and operator nodes: what
    ast.walk gives, without its generators (a big kernel's statements are walked several
    times, and ast.walk was most of lowering one)."""
    out, i = [node], 0
    append = out.append
    while i < len(out):
        n = out[i]
        i += 1
        cls = type(n)
        fields = _CHILD_FIELDS.get(cls)
        if fields is None:
            fields = _CHILD_FIELDS[cls] = tuple(f for f in cls._fields if f not in _LEAF_FIELDS)
        for field in fields:
            value = getattr(n, field, None)
            if type(value) is list:
                for item in value:
                    if isinstance(item, ast.AST):
                        append(item)
            elif isinstance(value, ast.AST):
                append(value)
    return out


def _names_read(node):
    return {n.id for n in _walk(node) if type(n) is ast.Name and type(n.ctx) is ast.Load}


def _plain_assignment(stmt):
    """An assignment of arithmetic to names or array elements: no call but math functions
    and pure builtins, no tuple unpacking (what a piece may hold)."""
    if not isinstance(stmt, ast.Assign):
        return False
    for t in stmt.targets:
        if not (isinstance(t, ast.Name) or (isinstance(t, ast.Subscript)
                                            and isinstance(t.value, ast.Name))):
            return False
    for node in _walk(stmt.value):
        if isinstance(node, ast.Call):
            f = node.func
            if isinstance(f, ast.Name) and f.id in _PURE_BUILTINS:
                continue
            if isinstance(f, ast.Attribute) and isinstance(f.value, ast.Name) \
                    and f.value.id == "math":
                continue
            return False
        if isinstance(node, (ast.Lambda, ast.NamedExpr)):
            return False
    return True


class _PieceLowering(FunctionLowering):
    """A run of plain assignments of ``parent`` as a function of its own: arguments the
    frame (double*) and the parent's arrays in scope; its inputs are loaded from the frame, its
    outputs stored there."""

    def __init__(self, parent, stmts, inputs, outputs, arrays):
        super().__init__(parent.owner, parent.node, parent.globs, (), f"{parent.name}_piece")
        self.parent, self.stmts = parent, stmts
        self.inputs, self.outputs, self.arrays = inputs, outputs, arrays
        self.declared = parent.declared
        self.single = parent.single

    def lower(self):
        arg_types = [F64P]
        for _, array in self.arrays:
            arg_types.append(F64P)
            arg_types.extend([I64] * array.ndim)
        fn = ir.Function(self.owner.module, ir.FunctionType(ir.VoidType(), arg_types),
                         name=self.owner.module.get_unique_name(self.name))
        fn.linkage = "internal"
        fn.attributes.add("noinline")
        self.fn = fn
        self.entry = fn.append_basic_block("entry")
        body = fn.append_basic_block("body")
        self.b = ir.IRBuilder(body)
        args = iter(fn.args)
        frame = next(args)
        for name, array in self.arrays:
            data = next(args)
            self.vars[name] = Array(data, [next(args) for _ in range(array.ndim)])
        slots = self.parent.frame_slots
        for name in self.inputs:
            value = self.b.load(self.b.gep(frame, [ir.Constant(I64, slots[name])]))
            if name in self.single:
                self.vars[name] = ("f", None, value)
            else:                       # the piece may assign it again: a slot of its own
                self._store_scalar(name, "f", value)
        self._block(self.stmts)
        for name in self.outputs:
            kind, value = self._e_Name(ast.Name(id=name, ctx=ast.Load()))
            self.b.store(self.cast(value, kind, "f"),
                         self.b.gep(frame, [ir.Constant(I64, slots[name])]))
        self.b.ret_void()
        ir.IRBuilder(self.entry).branch(body)
        return fn


def _load(target):
    """The expression that reads an augmented assignment's target."""
    node = ast.fix_missing_locations(ast.copy_location(
        type(target)(**{f: getattr(target, f) for f in target._fields}), target))
    if hasattr(node, "ctx"):
        node.ctx = ast.Load()
    return node


class _KindPass:
    """The kind a function returns, found without lowering: the kinds of its names follow its
    assignments in order (a loop target is an integer, an integer name assigned a float
    becomes a float), and each return's kind is unified (int with bool is int; with a float,
    float)."""

    def __init__(self, lowering):
        self.lw = lowering
        self.env = {}
        for a, kind in zip(lowering.node.args.args, lowering.arg_sig):
            self.env[a.arg] = kind if not isinstance(kind, tuple) else ("a", kind[1])
        self.found = []

    def kind(self):
        self._block(self.lw.node.body)
        found = set(self.found)
        if found <= {None}:
            return None
        if None in found:
            self.lw.fail(self.lw.node, "returns both with and without a value")
        if "?" in found:
            self.lw.fail(self.lw.node, "a return of something that is not a number")
        if "f" in found:
            return "f"
        return "i" if "i" in found else "b"

    def _block(self, stmts):
        for s in stmts:
            if isinstance(s, ast.Return):
                self.found.append(None if _returns_nothing(s) else self.of(s.value))
            elif isinstance(s, ast.Assign):
                k = self.of(s.value)
                for t in s.targets:
                    self._bind(t, k, s.value)
            elif isinstance(s, ast.AugAssign) and isinstance(s.target, ast.Name):
                self._bind(s.target, _unify(self.env.get(s.target.id), self.of(s.value)), None)
            elif isinstance(s, ast.If):
                self._block(s.body)
                self._block(s.orelse)
            elif isinstance(s, ast.For):
                if isinstance(s.target, ast.Name):
                    if isinstance(s.iter, ast.Tuple) and s.iter.elts:
                        self.env[s.target.id] = self.of(s.iter.elts[0])
                    else:
                        self.env[s.target.id] = "i"
                self._block(s.body)

    def _bind(self, target, kind, value):
        if isinstance(target, ast.Name):
            old = self.env.get(target.id)
            self.env[target.id] = kind if old is None or not isinstance(old, str) \
                else _unify(old, kind)
        elif isinstance(target, ast.Tuple) and isinstance(value, ast.Tuple):
            for t, v in zip(target.elts, value.elts):
                self._bind(t, self.of(v), v)

    def of(self, node):
        """The kind of an expression: "f", "i", "b", ("a", ndim), or "?"."""
        if isinstance(node, ast.Constant):
            v = node.value
            return "b" if isinstance(v, bool) else "i" if isinstance(v, int) else \
                "f" if isinstance(v, float) else "?"
        if isinstance(node, ast.Name):
            if node.id in self.env:
                return self.env[node.id]
            v = self.lw.globs.get(node.id)
            array = _float_array(v)
            if array is not None:
                return ("a", array.ndim)
            return "b" if isinstance(v, bool) else "i" if isinstance(v, int) else \
                "f" if isinstance(v, float) else "?"
        if isinstance(node, (ast.Compare, ast.BoolOp)) or (
                isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.Not)):
            return "b"
        if isinstance(node, ast.UnaryOp):
            k = self.of(node.operand)
            return "i" if k == "b" else k
        if isinstance(node, ast.BinOp):
            left, right = self.of(node.left), self.of(node.right)
            if isinstance(node.op, (ast.Div, ast.Pow)) or "f" in (left, right):
                return "f"
            return "i"
        if isinstance(node, ast.IfExp):
            return _unify(self.of(node.body), self.of(node.orelse))
        if isinstance(node, ast.Subscript):
            base = self.of(node.value)
            if isinstance(base, tuple) and base[0] == "a":
                n = len(node.slice.elts) if isinstance(node.slice, ast.Tuple) else 1
                return ("a", base[1] - n) if n < base[1] else "f"
            return "?"
        if isinstance(node, ast.Call):
            f = node.func
            if isinstance(f, ast.Attribute) and isinstance(f.value, ast.Name) \
                    and self.lw.globs.get(f.value.id) is math:
                return "b" if f.attr in ("isfinite", "isnan", "isinf") else "f"
            if isinstance(f, ast.Name):
                if f.id in ("abs", "max", "min") and f.id not in self.lw.globs:
                    kinds = [self.of(a) for a in node.args]
                    return "f" if "f" in kinds else "i"
                if f.id == "float":
                    return "f"
                target = self.lw.globs.get(f.id)
                if callable(target):
                    sig = []
                    for a in node.args:
                        k = self.of(a)
                        sig.append(k if isinstance(k, str) else ("a", k[1]))
                    if "?" in sig:
                        return "?"
                    _, ret = self.lw.owner.internal(target, tuple(sig))
                    return ret if ret is not None else "?"
        return "?"


def _single_assignments(fn_node):
    """Names assigned exactly once in the function, by a statement of its top-level block
    (not a parameter, a loop target, an augmented assignment or inside a branch or loop)."""
    counts, top = {}, set()

    def targets(t):
        if isinstance(t, ast.Name):
            yield t.id
        elif isinstance(t, ast.Tuple):
            for e in t.elts:
                yield from targets(e)

    for node in _statements_in(fn_node):
        names = []
        if isinstance(node, ast.Assign):
            for t in node.targets:
                names.extend(targets(t))
        elif isinstance(node, (ast.AugAssign, ast.For)):
            names.extend(targets(node.target))
            names.extend(targets(node.target))       # never single
        for name in names:
            counts[name] = counts.get(name, 0) + 1
    for stmt in fn_node.body:
        if isinstance(stmt, ast.Assign):
            for t in stmt.targets:
                top.update(targets(t))
    params = {a.arg for a in fn_node.args.args}
    return frozenset(n for n in top if counts.get(n) == 1 and n not in params)


def _statements_in(fn_node) -> list:
    """Every statement of a function, those in branches and loops included (assignments are
    statements: the subset has no assignment expressions)."""
    out, todo = [], list(fn_node.body)
    while todo:
        stmt = todo.pop()
        out.append(stmt)
        for field in ("body", "orelse", "finalbody"):
            todo.extend(getattr(stmt, field, ()) or ())
        for handler in getattr(stmt, "handlers", ()) or ():
            todo.extend(handler.body)
    return out


def _float_array(value):
    """``value`` as a C-contiguous float64 numpy array when it is a float array, else None."""
    import numpy as np
    if isinstance(value, np.ndarray) and value.dtype == np.float64:
        return np.ascontiguousarray(value)
    return None


def _int_array(value):
    """``value`` when it is a 1-D integer numpy array, else None."""
    import numpy as np
    if isinstance(value, np.ndarray) and value.ndim == 1 and value.dtype.kind in "iu":
        return value
    return None


def _returns_nothing(node):
    """``return`` or ``return None``."""
    return node.value is None or (isinstance(node.value, ast.Constant)
                                  and node.value.value is None)


def _unify(a, b):
    if a is None:
        return b
    if a == b:
        return a
    if {a, b} <= {"f", "i", "b"}:
        return "f" if "f" in (a, b) else "i"
    return "?"
