"""Registry of stepper methods and the glue each one emits into a generated module.

Why glue: numba caches a compiled function on disk only when it takes no function arguments.
The cores in ``steppers/<method>.py`` are generic over the kernels: they receive the generated
module itself as their first argument (``kern``; see base.py for why a module and not the
dispatchers), so they cannot be cached on their own. The glue ``run_<method>`` lives in the
generated module, passes that module and takes only arrays and scalars, so it is ``cache=True``
and its compiled code, cores included, is loaded from numba's cache by the next process. The
KEY of a generated module hashes the sources of the steppers it glues and of the package
modules they import (codegen.needs.source_closure), so a change there regenerates the module
and thereby invalidates that cache.

Glue signature (identical for every method)::

    run_<method>(q0, v0, t0, h, n_steps, save_every, p, settings,
                 out_t, out_q, out_v, out_stats, out_extra, out_last) -> (status, steps_done)

    q0, v0     (n,) float64      initial state at time t0
    h          float             step (may be negative: steps backwards in time)
    n_steps, save_every  int     saves after every save_every-th step, plus row 0
    p          (n_params,)       parameter values in PARAMS order
    settings   (N_SETTINGS,)     base.make_settings(newton_tol, max_iter, bound, mode)
    out_t (S,), out_q (S, n), out_v (S, n), out_stats (S, N_STATS), out_extra (S, n_extra)
               S = n_steps // save_every + 1; n_extra = 0 for the unconstrained methods, the
               element states of nonsmooth_euler, m + 2 (multipliers, max|Phi|, max|J v|) for
               the constrained methods (steppers/constrained.py)
    out_last   (2 n + 3 + n_total,)  [t, q, v, Newton iterations since the last save, Newton
                                 residual, the method's extra buffer] at the end, or at the
                                 failure; n_total >= n_extra sizes that buffer (scratch after
                                 the saved entries; see base.run_loop)
    status     lagrange_gen.status code; steps_done = index of the failing step on failure, -1
               when the initial state is refused (see base.run_loop)

The glue is compiled with error_model="numpy", like the kernels and the cores: non-finite
arithmetic gives inf/NaN, which the run loop reports as NON_FINITE, never a Python exception.
"""

from __future__ import annotations

from dataclasses import dataclass

METHODS = ("explicit_euler", "symplectic_euler", "verlet", "midpoint", "implicit_euler", "rk4",
           "composition", "nonsmooth_euler", "rattle", "constrained_midpoint",
           "constrained_implicit_euler", "spook", "index1")

#: Methods for models with holonomic constraints (extra = multipliers and residuals, see
#: steppers/constrained.py); simulate() refuses every other method on a constrained model and
#: these on an unconstrained one. index1 is the acceleration-level formulation that drifts,
#: kept as the documented bad example.
CONSTRAINED_METHODS = ("rattle", "constrained_midpoint", "constrained_implicit_euler", "spook",
                       "index1")

#: Methods that treat nonsmooth elements (SaintVenant, DryFriction); simulate() routes
#: implicit_euler to nonsmooth_euler on models that have elements.
NONSMOOTH_METHODS = ("nonsmooth_euler",)

#: Which models each method applies to, as data (what simulate() accepts; it reads the two
#: tuples above): ``constraints`` True = only models with holonomic constraints, False = only
#: models without; ``elements`` True = treats nonsmooth elements (the only methods for models
#: with elements; on a model without them nonsmooth_euler is implicit Euler, and simulate and
#: the convergence tests run it there). The generator emits glue for the methods that apply.
APPLIES = {m: {"constraints": m in CONSTRAINED_METHODS, "elements": m in NONSMOOTH_METHODS} for m in METHODS}

#: The method simulate() runs instead of the one asked for on a model with nonsmooth elements.
ON_ELEMENTS = {"implicit_euler": "nonsmooth_euler"}


def runs_as(method: str, n_elements: int) -> str:
    """The method whose glue runs ``method`` on a model with ``n_elements`` nonsmooth elements."""
    return ON_ELEMENTS.get(method, method) if n_elements else method


def inapplicable(method: str, n_constraints: int, n_elements: int) -> str:
    """Why ``method`` (after runs_as) does not apply to a model with these counts, or ""."""
    flags = APPLIES[method]
    if n_constraints and n_elements:
        return "constraints together with nonsmooth elements are not supported by any method"
    if bool(n_constraints) != flags["constraints"]:
        return ("it ignores the model's constraints" if n_constraints
                else "it is for models with constraints and this model has none")
    if n_elements and not flags["elements"]:
        return "it cannot treat the model's nonsmooth elements (implicit_euler runs nonsmooth_euler)"
    return ""


def applicable_methods(n_constraints: int, n_elements: int) -> tuple:
    """The methods that apply to a model with these counts, in METHODS order."""
    return tuple(m for m in METHODS if not inapplicable(m, n_constraints, n_elements))


GLUE_ARGS = ("q0, v0, t0, h, n_steps, save_every, p, settings, "
             "out_t, out_q, out_v, out_stats, out_extra, out_last")


@dataclass(frozen=True)
class MethodInfo:
    """What the tests and reports may rely on for a method. ``stable``: the linear stability
    range in tau = h omega (README's steppers table, reports/stability.md; closed forms in
    bench.stability), quoted by simulate's energy warning; "" for the constrained methods."""

    order: int
    symplectic: bool
    symmetric: bool
    implicit: bool
    summary: str
    stable: str = ""


INFO = {
    "explicit_euler": MethodInfo(1, False, False, False, "forward Euler (what not to do)",
                                 "unstable for every tau > 0 (rho = sqrt(1 + tau^2))"),
    "symplectic_euler": MethodInfo(1, True, False, True, "symplectic Euler A in (q, p = H v)",
                                   "stable for tau < 2"),
    "verlet": MethodInfo(2, True, True, True, "velocity Verlet / generalized leapfrog",
                         "stable for tau < 2"),
    "midpoint": MethodInfo(2, True, True, True, "midpoint variational integrator (A-stable)",
                           "linearly stable for every tau (rho = 1), accurate only for tau << 1"),
    "implicit_euler": MethodInfo(1, False, False, True, "backward Euler (L-stable)",
                                 "stable for every tau, damping (rho = 1/sqrt(1 + tau^2))"),
    "rk4": MethodInfo(4, False, False, False, "classical Runge-Kutta 4",
                      "stable for tau <= 2.83 (2 sqrt(2))"),
    "composition": MethodInfo(4, True, True, True, "Yoshida 4th-order triple jump of verlet",
                              "stable for tau < 1.57"),
    "nonsmooth_euler": MethodInfo(1, False, False, True,
                                  "implicit Euler with Saint-Venant return map and Moreau-Jean friction"),
    "rattle": MethodInfo(2, True, True, True, "constrained Verlet, Newton on the multipliers"),
    "constrained_midpoint": MethodInfo(2, True, True, True,
                                       "midpoint variational integrator with constraints"),
    "constrained_implicit_euler": MethodInfo(1, False, False, True,
                                             "index-3 backward Euler with velocity projection"),
    "spook": MethodInfo(1, False, False, True,
                        "Lacoursiere's regularized linearly implicit stepper (compliance, relaxation)"),
    "index1": MethodInfo(4, False, False, False,
                         "rk4 on the acceleration-level KKT form (drifts: the bad example)"),
}

# _THIS_MODULE (this generated module, typed by numba as a compile-time constant) is what the
# cores call kernels through; assigning it in every glue block keeps each block self-contained.
_GLUE = '''import sys as _sys

from lagrange_gen.steppers import {method} as _stepper_{method}

_THIS_MODULE = _sys.modules[__name__]


@njit(cache=True, error_model="numpy")
def run_{method}({wrapped}):
    """Integrate with {method} ({summary}); returns (status, steps_done).

    Argument shapes: see lagrange_gen.steppers.registry; lagrange_gen.simulate wraps this."""
    return _stepper_{method}.run(_THIS_MODULE, {wrapped_call})'''


def glue_source(method: str) -> str:
    """Source text of ``run_<method>`` to append to a generated module (deterministic)."""
    if method not in INFO:
        raise KeyError(f"unknown stepper method {method!r}; known: {', '.join(METHODS)}")
    indent = " " * (len(f"def run_{method}("))
    wrapped = GLUE_ARGS.replace("settings, ", "settings,\n" + indent)
    call_indent = " " * len(f"    return _stepper_{method}.run(")
    wrapped_call = GLUE_ARGS.replace("settings, ", "settings,\n" + call_indent)
    return _GLUE.format(method=method, wrapped=wrapped, wrapped_call=wrapped_call,
                        summary=INFO[method].summary)
