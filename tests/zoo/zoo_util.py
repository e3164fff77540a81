"""Helpers of the zoo tests: the method list, runs through lagrange_gen.simulate, order fits.

Every zoo model is unconstrained and has no nonsmooth element, so the methods that apply are the
registry's methods minus the constrained and the nonsmooth ones (taken from the registry, so a new
stepper is tested here without editing this file). Each test module generates its model once per
session through the top-level ``generated`` fixture; numba compiles a run_<method> only when a
test calls it.

Tolerances: order fits compare log-log slopes with the method's order (registry.INFO); quantities
a method keeps to roundoff are bounded by roundoff_bound, one rounding of the quantity per step.
"""

import numpy as np

from lagrange_gen import simulate
from lagrange_gen.steppers.core.registry import CONSTRAINED_METHODS, INFO, METHODS, NONSMOOTH_METHODS

# Fixed-step methods (order fits at given step counts); dop853 chooses its own steps and is
# checked in tests/steppers/test_dop853.py and tests/events.
UNCONSTRAINED_METHODS = tuple(m for m in METHODS
                              if m not in CONSTRAINED_METHODS and m not in NONSMOOTH_METHODS
                              and not INFO[m].adaptive and not INFO[m].contacts and not INFO[m].nonholonomic)
SYMPLECTIC_METHODS = tuple(m for m in UNCONSTRAINED_METHODS if INFO[m].symplectic)
EPS = np.finfo(np.float64).eps

#: A fitted order must be within this of the expected one (step counts are chosen in the
#: asymptotic range of every method, where the measured slopes are within 0.1 of it).
ORDER_SLACK = 0.3
#: Errors of the O(1) zoo quantities at or below this are round-off, not truncation.
ROUNDOFF_FLOOR = 1e-12


def order(method):
    return INFO[method].order


def assert_model_allows_every_method(mod):
    """The zoo runs every unconstrained method: the model must have neither constraints nor
    nonsmooth elements (simulate would refuse or reroute the methods otherwise)."""
    assert getattr(mod, "N_CONSTRAINTS", 0) == 0 and getattr(mod, "N_ELEMENTS", 0) == 0
    assert set(UNCONSTRAINED_METHODS) <= set(mod.METHODS)


def run(mod, method, q0, v0, t_end, n_steps, params, save_every=1, **options):
    """Trajectory of n_steps steps of size t_end / n_steps (the final state is always saved);
    options go to lagrange_gen.simulate (newton_always=False, the default, only to the methods
    that have the setting)."""
    if not options.get("newton_always", True):
        del options["newton_always"]
    return simulate(mod, method, q0, v0, t_end=t_end, h=t_end / n_steps, params=params,
                    save_every=save_every, **options)


def fitted_order(step_counts, errors):
    """Slope of log(error) against log(h) for h proportional to 1 / step_counts."""
    h = 1.0 / np.asarray(step_counts, dtype=float)
    return float(np.polyfit(np.log(h), np.log(np.asarray(errors, dtype=float)), 1)[0])


def assert_orders(method, step_counts, errors, expected, at_least=()):
    """errors: {quantity: [error per step count]}; expected: {quantity: order}. Every fitted
    order within ORDER_SLACK of the expected one, or for the quantities in at_least not below it
    by more than ORDER_SLACK (an error that is O(h^p) by theorem and converges faster on the
    case at hand). Errors at or below ROUNDOFF_FLOOR are left out of the fit; a quantity with
    fewer than two errors above it must stay below 100 ROUNDOFF_FLOOR. The message lists every
    fit. Returns {quantity: fitted order}."""
    fits = {}
    for name, errs in errors.items():
        above = [(n, e) for n, e in zip(step_counts, errs) if e > ROUNDOFF_FLOOR]
        if len(above) >= 2:
            fits[name] = fitted_order(*zip(*above))
        else:      # a 6th-order method reaches round-off at the coarsest steps: no order to fit
            assert max(errs) <= 100 * ROUNDOFF_FLOOR, (method, name, errs)
            fits[name] = expected[name]
    report = "; ".join(f"{name}: order {fits[name]:.2f} (expected {expected[name]}"
                       + ("+" if name in at_least else "") + "), errors "
                       + ", ".join(f"{e:.2e}" for e in errors[name]) for name in fits)
    print(f"{method}: {report}")    # shown by pytest -rP: the fitted orders of a passing run
    bad = [name for name in fits if fits[name] < expected[name] - ORDER_SLACK
           or (name not in at_least and fits[name] > expected[name] + ORDER_SLACK)]
    assert not bad, f"{method}, steps {list(step_counts)}: {report}"
    return fits


def roundoff_bound(scale, n_steps):
    """Largest change of a quantity of size ``scale`` that a method keeps exactly in exact
    arithmetic: at most one rounding of it per step, eps * scale * n_steps."""
    return EPS * abs(scale) * max(n_steps, 1)
