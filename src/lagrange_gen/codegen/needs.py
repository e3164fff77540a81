"""Which generated kernels a stepper method needs, read from the steppers' source (AST).

A stepper core reaches the generated module only as ``kern`` (see steppers/core/run_loop.py), so the
kernels a method needs are the attributes ``kern.<name>`` accessed by the functions of
``steppers/methods/<method>.py`` and, transitively, by every function of the package they call
(``from ..core.legendre import accel``, ``verlet.step`` through ``from . import verlet``, ...). Reading
the source instead of keeping a table means a newly added method (rattle, spook, ...) is
specialized correctly without touching the generator. The analysis is conservative: a kernel
used on any branch counts (numba types every branch, so it must exist to compile).
"""

from __future__ import annotations

import ast
from functools import lru_cache

from ..jit.sources import module_path, relative_module

_KERN = "kern"                                         # the parameter naming the generated module

#: What a loop function reaches besides its own calls: run_loop.run_loop calls the stepping loop
#: it is passed (run_loop.stepping_loop, a closure the glue binds), whose body is run_loop.steps.
_PASSED_IN = {("steppers.core.run_loop", "run_loop"): [("steppers.core.run_loop", "steps")]}


def method_needs(method: str, with_loop: bool = True) -> frozenset:
    """Names ``kern.<name>`` used by ``steppers/methods/<method>.py`` and everything it calls, and
    (with_loop) by the run loop its glue calls (run_loop.run_loop or adaptive.run_adaptive: the
    energy, events, ...). SPEC.kernels declares the method's own (with_loop=False)."""
    from ..steppers.core.registry import LOOPS, spec
    module = f"steppers.methods.{method}"
    roots = [(module, name) for name in _parse(module).functions]
    if with_loop:
        loop_module, loop = LOOPS[spec(method).adaptive]
        roots.append((f"steppers.core.{loop_module}", loop))
        roots += _PASSED_IN.get(roots[-1], [])
    return _reached(roots)


def _reached(roots) -> frozenset:
    """kern attributes reached from the (module, function) roots through calls."""
    seen, needs = set(), set()
    while roots:
        key = roots.pop()
        if key in seen:
            continue
        seen.add(key)
        info = _parse(key[0])
        fn = info.functions.get(key[1])
        if fn is None:
            continue
        needs |= fn.kern_attrs
        roots += [target for target in (info.resolve(c) for c in fn.calls) if target]
        # A module-level Newton problem (newton.problem(name, ...)) the function passes on.
        roots += [(key[0], f) for n in fn.names if n in info.problems for f in info.problems[n]]
    return frozenset(needs)


def sensitivity_needs(method: str) -> frozenset:
    """Names ``kern.<name>`` a forward-sensitivity run of ``method`` reaches: the method's own
    step (steppers/methods/<method>.py), its tangent step (steppers/sensitivity/<method>.py)
    and the loop running both (steppers/sensitivity/core.py sensitivity_loop)."""
    module = f"steppers.sensitivity.{method}"
    roots = [(module, name) for name in _parse(module).functions]
    roots.append(("steppers.sensitivity.core", "sensitivity_loop"))
    return method_needs(method, with_loop=False) | _reached(roots)


def methods_needs(methods) -> dict:
    """{method: sorted tuple of kern attributes} for several methods."""
    return {m: tuple(sorted(method_needs(m))) for m in methods}


class _Function:
    def __init__(self, node):
        self.kern_attrs, self.calls, self.names = set(), [], set()
        for sub in ast.walk(node):
            if isinstance(sub, ast.Name):
                self.names.add(sub.id)
            if isinstance(sub, ast.Attribute) and isinstance(sub.value, ast.Name) and sub.value.id == _KERN:
                self.kern_attrs.add(sub.attr)
            elif isinstance(sub, ast.Call):
                if isinstance(sub.func, ast.Name):
                    self.calls.append((None, sub.func.id))
                elif isinstance(sub.func, ast.Attribute) and isinstance(sub.func.value, ast.Name):
                    self.calls.append((sub.func.value.id, sub.func.attr))


class _Module:
    """Top-level functions of one package module and its imports, for call resolution."""

    def __init__(self, dotted, tree):
        self.dotted = dotted
        self.functions = {n.name: _Function(n) for n in tree.body if isinstance(n, ast.FunctionDef)}
        # NAME = newton.problem("...", assemble_fn, residual=..., jacobian=...): the functions
        # newton.solve / solve_simplified(NAME, ...) call.
        self.problems = {}
        for node in tree.body:
            value = getattr(node, "value", None)
            if (isinstance(node, ast.Assign) and isinstance(value, ast.Call)
                    and isinstance(value.func, ast.Attribute) and value.func.attr == "problem"):
                functions = [a.id for a in value.args[1:] if isinstance(a, ast.Name)]
                functions += [k.value.id for k in value.keywords if isinstance(k.value, ast.Name)]
                for target in node.targets:
                    if isinstance(target, ast.Name):
                        self.problems[target.id] = functions
        self.names, self.modules = {}, {}   # imported function name -> module; alias -> module
        for node in tree.body:
            if isinstance(node, ast.ImportFrom) and node.level:
                base = relative_module(dotted, node.level, node.module)
                for alias in node.names:
                    child = f"{base}.{alias.name}" if base else alias.name
                    if module_path(child) is not None:
                        self.modules[alias.asname or alias.name] = child
                    else:
                        self.names[alias.asname or alias.name] = (base, alias.name)

    def resolve(self, call):
        """(module, function) a call refers to inside the package, or None."""
        owner, name = call
        if owner is None:
            if name in self.functions:
                return self.dotted, name
            return self.names.get(name)
        if owner in self.modules:
            return self.modules[owner], name
        return None


@lru_cache(maxsize=None)
def _parse_cached(dotted, mtime):
    path = module_path(dotted)
    return _Module(dotted, ast.parse(path.read_text(), str(path)))


def _parse(dotted):
    """Parsed module (cached per file modification time: steppers change while we run)."""
    path = module_path(dotted)
    if path is None:
        return _Module(dotted, ast.Module(body=[], type_ignores=[]))
    return _parse_cached(dotted, path.stat().st_mtime_ns)


#: Functions every generated module defines besides the kernels (a stepper may call them).
MODULE_FUNCTIONS = ("forward_dynamics",)


def select_kernels(dyn, methods, sensitivities=False) -> dict:
    """{kernel name: why it is emitted} for a model and the requested methods, in table order.

    Why: the methods whose steppers reach it (``kern.<name>``), or the Python-side use that
    every module of this model needs (forward dynamics, saved energy, consistent initial
    conditions of constrained models, element energy); with ``sensitivities``, also what the
    forward sensitivities of each method that has them reach (sensitivity_needs: the parameter
    derivatives). A method needing a name that is neither
    a kernel nor a module function is a GenerationError naming both. No methods at all (an
    empty list, not None) asks for a kernel library without steppers: every kernel is emitted.
    """
    from ..errors import GenerationError
    from .spec import (CONSTRAINED_NONHOLONOMIC_LINEARIZE, CORE_KERNELS, NONHOLONOMIC_LINEARIZE,
                       ROBOT_KERNELS, default_kernels, kernel_table)
    table = kernel_table(dyn)
    if not methods:
        return {name: ["no stepper requested: kernel library"] for name in default_kernels(dyn)}
    why = {name: ["always (forward dynamics, energy, Legendre transform)"] for name in CORE_KERNELS}
    if dyn.mass_is_constant:
        why.setdefault("rhs", []).append("constant H: forward dynamics with the factor from import")
    if dyn.m:
        why.setdefault("constraints", []).append("constrained model (consistent initial conditions)")
        why.setdefault("constraint_rate", []).append("constrained model (consistent initial velocities)")
    if dyn.n_nonholonomic:
        for name in NONHOLONOMIC_LINEARIZE + (CONSTRAINED_NONHOLONOMIC_LINEARIZE if dyn.m else ()):
            why.setdefault(name, []).append("model with nonholonomic constraints (linearize)")
    if dyn.n_elements:
        why.setdefault("elements", []).append("model with nonsmooth elements (element energy)")
    if hasattr(dyn.jac, "inverse_dynamics"):
        for name in ROBOT_KERNELS + ("rhs_jacobian", "mass_matvec_dq"):
            why.setdefault(name, []).append("model built from bodies (robotics kernels)")
    if {"input_jacobian", "outputs"} & set(table):   # inputs or outputs: run/control.py, linearize
        for name in ("input_jacobian", "outputs", "output_jacobian", "rhs_jacobian",
                     "mass_matvec_dq") + (("constraint_dq",) if dyn.m else ()):
            if name in table:
                why.setdefault(name, []).append("model inputs/outputs (saved outputs, linearize)")
    needs = methods_needs(methods)
    if sensitivities:
        from ..steppers.sensitivity import SENSITIVITY_METHODS
        for method in (m for m in methods if m in SENSITIVITY_METHODS):
            needs[f"{method} sensitivities"] = tuple(sorted(sensitivity_needs(method)))
    for method, names in needs.items():
        for name in names:
            if name.isupper() or name in MODULE_FUNCTIONS:
                continue           # module constants and functions are always present
            if name not in table:
                raise GenerationError(f"stepper {method} uses kern.{name}, which lagrange-gen does not "
                                      f"generate (kernels: {', '.join(table)})")
            why.setdefault(name, []).append(method)
    return {name: why[name] for name in table if name in why}
