"""What simulate works out from a generated module and a method alone, worked out once.

A warm ``simulate`` call on a small model costs little more than its checks and bookkeeping,
and part of that depends only on the module and the method asked for, both immutable once
loaded: which method runs (``element_method``), whether it applies to the model
(consistent.check_method), its spec, the width of its saved fields and their layout, its
settings record when none are given, and the parameter vector when neither ``params`` nor
``control`` is given. ``method_plan`` works these out on the first call of a (module, method)
and keeps them while the module lives (a weak reference: a module dropped by its user is not
held here). A refusal is never kept: a call that is refused is refused again, with the same
line, on every call.
"""

from __future__ import annotations

import weakref
from typing import NamedTuple

from ..errors import SimulationError
from ..steppers.core import registry
from ..steppers.core.method_spec import make_settings


class MethodPlan(NamedTuple):
    """What a (module, method) pair fixes for every run of it."""

    runs: str                 # the method that actually runs (element_method)
    spec: object              # its Spec
    n_saved: int              # width of its saved fields (extra buffer columns)
    layout: tuple             # ((name, start, width), ...) of those fields
    default_settings: tuple   # its settings record when no setting is given
    default_params: object    # p (n_params,) with no params= and no control=, or None when
    #                           that run is refused (a parameter or an input without a value)


#: {module: {method asked for: MethodPlan}}
_PLANS: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()


def element_method(module, method):
    """The method that actually runs: on a model with nonsmooth elements a method that a
    nonsmooth one stands in for (SPEC.stands_in_for) becomes it; a method that cannot treat
    them is refused, naming them."""
    names = tuple(getattr(module, "ELEMENTS", ()))
    runs = registry.runs_as(method, len(names)) if method in registry.METHODS else method
    if not names or runs not in registry.METHODS or registry.spec(runs).elements:
        return runs
    use = "; ".join(f"method={asked!r} (runs {m}: {registry.spec(m).summary})"
                    for asked, m in registry.ON_ELEMENTS.items())
    raise SimulationError(
        f"{module.NAME}: method {method!r} cannot treat the nonsmooth element(s) "
        f"{', '.join(names)} (no silent regularization); use {use}")


def method_plan(module, method) -> MethodPlan:
    """The MethodPlan of running ``method`` (one of registry.METHODS) on ``module``, kept after
    the first call; SimulationError (element_method, consistent.check_method) when the method
    cannot run on the model."""
    try:
        kept = _PLANS.get(module)
    except TypeError:               # an object without weak references (a hand-made module)
        return make_plan(module, method)
    plan = kept.get(method) if kept is not None else None
    if plan is None:
        plan = make_plan(module, method)
        _PLANS.setdefault(module, {})[method] = plan
    return plan


def make_plan(module, method) -> MethodPlan:
    """Work out a MethodPlan (method_plan keeps it)."""
    from .consistent import check_method
    from .control import resolve_inputs
    runs = element_method(module, method)
    check_method(module, runs)
    spec = registry.spec(runs)
    layout = spec.saved_layout(module.N_COORDS, module.N_CONSTRAINTS, module.N_ELEMENTS,
                               getattr(module, "N_CONTACTS", 0),
                               getattr(module, "N_NONHOLONOMIC", 0))
    try:
        params = resolve_inputs(module, None, None, 0.0)[0]
    except SimulationError:         # refused on each call by resolve_inputs itself
        params = None
    if params is not None:
        params.setflags(write=False)
    return MethodPlan(runs, spec, sum(w for _, _, w in layout), layout,
                      make_settings(spec, {}), params)


def run_params(plan, module, params, control, control_params, h, t0, q, v):
    """(p (n_params,), hook, data) of a run (control.resolve_inputs): a fresh copy of the
    plan's parameters when neither params, control nor control_params is given (the loop of a
    run with inputs writes into p), else resolve_inputs' answer."""
    if params is None and control is None and control_params is None and \
            plan.default_params is not None:
        return plan.default_params.copy(), None, None
    from .control import resolve_inputs
    return resolve_inputs(module, params, control, h, t0, q, v, control_params)
