"""Registry of stepper methods: the list, each method's Spec, and which methods apply to a model.

Everything about a method is declared by its module's SPEC (steppers/methods/<method>.py,
core/method_spec.py); this module lists the methods in report order and answers the questions
simulate, the CLI and the generator ask about them. The glue a generated module runs them
through is written by lagrange_gen.codegen.glue.
"""

from __future__ import annotations

import importlib

#: The registry: one line per method, in the order reports list them. Everything else about a
#: method is declared by its module's SPEC (method_spec.py).
METHODS = ("explicit_euler", "symplectic_euler", "verlet", "midpoint", "implicit_euler", "rk4",
           "dop853", "composition", "composition6", "nonsmooth_euler", "rattle",
           "constrained_midpoint", "constrained_implicit_euler", "spook", "index1", "moreau_jean",
           "spook_contacts", "dop853_impacts", "nonholonomic_rk4", "nonholonomic_midpoint")

#: {method: its Spec}.
INFO = {m: importlib.import_module(f"lagrange_gen.steppers.methods.{m}").SPEC for m in METHODS}

#: Methods for models with holonomic constraints (they save multipliers and residuals).
CONSTRAINED_METHODS = tuple(m for m in METHODS if INFO[m].constraints)

#: Methods for models with nonholonomic (velocity) constraints.
NONHOLONOMIC_METHODS = tuple(m for m in METHODS if INFO[m].nonholonomic)

#: Methods that treat nonsmooth elements (SaintVenant, DryFriction).
NONSMOOTH_METHODS = tuple(m for m in METHODS if INFO[m].elements)

#: Methods that choose their own steps (adaptive glue signature, simulate's rtol/atol/t_eval).
ADAPTIVE_METHODS = tuple(m for m in METHODS if INFO[m].adaptive)

#: Methods lagrange_gen.ensemble(..., device="cuda") runs (lagrange_gen.gpu): numba-cuda compiles
#: their prepare and step, the run loop's steps and the generated kernels for the GPU as they are
#: (tests/gpu lowers each for the CUDA target). Not yet: the compositions (their workspace is a
#: record of records, built by a jitted helper, which the member's local arrays do not express)
#: and dop853 (adaptive: no fixed-step ensemble runs it).
GPU_METHODS = ("explicit_euler", "symplectic_euler", "verlet", "midpoint", "implicit_euler", "rk4",
               "rattle", "constrained_midpoint", "constrained_implicit_euler", "spook", "index1",
               "nonsmooth_euler", "moreau_jean", "spook_contacts", "nonholonomic_rk4")

#: The method simulate() runs instead of the one asked for on a model with nonsmooth elements.
ON_ELEMENTS = {asked: m for m in NONSMOOTH_METHODS for asked in INFO[m].stands_in_for}


def unknown_method(method) -> str:
    """The one line for a method name that is not in METHODS: the closest names ("did you mean
    'midpoint'?") when some are close, and the known ones."""
    import difflib
    close = difflib.get_close_matches(str(method), METHODS, n=3, cutoff=0.6)
    guess = f"; did you mean {' or '.join(repr(m) for m in close)}? K" if close else "; k"
    return f"unknown method {method!r}{guess}nown: {', '.join(METHODS)}"


def spec(method: str):
    """The Spec of a method; KeyError naming the known ones."""
    if method not in INFO:
        raise KeyError(unknown_method(method))
    return INFO[method]


def runs_as(method: str, n_elements: int) -> str:
    """The method whose glue runs ``method`` on a model with ``n_elements`` nonsmooth elements."""
    return ON_ELEMENTS.get(method, method) if n_elements else method


def inapplicable(method: str, n_constraints: int, n_elements: int, n_contacts: int = 0,
                 n_nonholonomic: int = 0) -> str:
    """Why ``method`` (after runs_as) does not apply to a model with these counts, or ""."""
    flags = INFO[method]
    if n_nonholonomic and n_elements:
        return ("nonholonomic constraints together with nonsmooth elements are not supported by "
                "any method yet")
    if n_nonholonomic and n_contacts:
        both = [m for m in METHODS if INFO[m].contacts and INFO[m].nonholonomic_too
                and (INFO[m].holonomic_too or not n_constraints)]
        if not flags.nonholonomic_too:
            what = ("ignores the model's unilateral contacts" if flags.nonholonomic else
                    "does not treat nonholonomic constraints beside contacts")
            return f"it {what} (use {', '.join(both) or 'no method yet'})"
        return "" if not n_constraints or flags.holonomic_too else (
            f"it does not treat holonomic constraints beside contacts (use {', '.join(both)})")
    if bool(n_nonholonomic) != flags.nonholonomic:
        fits = [m for m in NONHOLONOMIC_METHODS if INFO[m].holonomic_too or not n_constraints]
        return (f"it ignores the model's nonholonomic constraints (use "
                f"{', '.join(fits)})" if n_nonholonomic
                else "it is for models with nonholonomic constraints and this model has none")
    if n_nonholonomic:
        both = [m for m in NONHOLONOMIC_METHODS if INFO[m].holonomic_too]
        return ("" if not n_constraints or flags.holonomic_too else
                f"it does not treat holonomic constraints beside nonholonomic ones (use "
                f"{', '.join(both)})")
    if n_constraints and n_elements:
        return "constraints together with nonsmooth elements are not supported by any method"
    if n_contacts and n_elements:
        return "contacts together with nonsmooth elements are not supported by any method yet"
    if bool(n_contacts) != flags.contacts:
        contact_methods = ", ".join(m for m in METHODS if INFO[m].contacts
                                    and (INFO[m].holonomic_too or not n_constraints))
        return (f"it ignores the model's unilateral contacts (use {contact_methods})" if n_contacts
                else "it is for models with unilateral contacts and this model has none")
    if n_contacts:
        both = [m for m in METHODS if INFO[m].contacts and INFO[m].holonomic_too]
        return ("" if not n_constraints or flags.holonomic_too else
                f"it does not treat holonomic constraints beside contacts (use {', '.join(both)})")
    if bool(n_constraints) != flags.constraints:
        return ("it ignores the model's constraints" if n_constraints
                else "it is for models with constraints and this model has none")
    if n_elements and not flags.elements:
        standins = [f"{a} runs {m}" for a, m in ON_ELEMENTS.items()]
        return ("it cannot treat the model's nonsmooth elements"
                + (f" ({', '.join(standins)})" if standins else ""))
    return ""


def applicable_methods(n_constraints: int, n_elements: int, n_contacts: int = 0,
                       n_nonholonomic: int = 0) -> tuple:
    """The methods that apply to a model with these counts, in METHODS order."""
    return tuple(m for m in METHODS
                 if not inapplicable(m, n_constraints, n_elements, n_contacts, n_nonholonomic))


#: The jitted loop each kind of method runs in: (module, function).
LOOPS = {False: ("run_loop", "run_loop"), True: ("adaptive", "run_adaptive")}
