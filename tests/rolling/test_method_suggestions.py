"""The methods a refusal suggests on a model with velocity constraints are the ones that run it.

The bicycle has holonomic constraints beside its nonholonomic ones: only the methods whose spec
says holonomic_too apply, and every message that names methods must name those (and no other).
The module is a stub with the counts check_method reads (no generation needed).
"""

import types

import pytest

from lagrange_gen.errors import SimulationError
from lagrange_gen.run.consistent import check_method
from lagrange_gen.steppers.core import registry


def _stub(n_constraints, n_nonholonomic):
    return types.SimpleNamespace(NAME="bike", N_CONSTRAINTS=n_constraints, N_ELEMENTS=0,
                                 N_CONTACTS=0, N_NONHOLONOMIC=n_nonholonomic,
                                 CONSTRAINTS=tuple(f"c{i}" for i in range(n_constraints)))


def _named_methods(message):
    return {m for m in registry.METHODS if m in message.replace(",", " ").replace("(", " ")
            .replace(")", " ").replace(":", " ").split()}


@pytest.mark.parametrize("method", [m for m in registry.METHODS
                                    if m not in ("nonholonomic_midpoint",)])
def test_bicycle_like_refusals_name_only_methods_that_apply(method):
    module = _stub(n_constraints=1, n_nonholonomic=2)
    applies = set(registry.applicable_methods(1, 0, 0, 2))
    assert applies == {"nonholonomic_midpoint"}
    with pytest.raises(SimulationError) as info:
        check_method(module, method)
    message = str(info.value)
    suggested = _named_methods(message) - {method}
    assert suggested == applies, message


def test_velocity_constraints_alone_suggest_both_nonholonomic_methods():
    with pytest.raises(SimulationError) as info:
        check_method(_stub(n_constraints=0, n_nonholonomic=2), "rk4")
    assert _named_methods(str(info.value)) - {"rk4"} == set(registry.NONHOLONOMIC_METHODS)
