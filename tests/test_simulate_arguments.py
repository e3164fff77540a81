"""What a newcomer meets first: simulate's help lists the methods, a misspelt method name gets a
suggestion, and a missing t_end or h is one SimulationError line naming the argument (not a
TypeError). None of these load or compile a model."""

import pytest

import lagrange_gen as lg
from lagrange_gen.errors import SimulationError
from lagrange_gen.steppers.core import registry

from lg_test_support import ROOT

CART = str(ROOT / "models" / "cart_pendulum.py")


def test_simulate_help_lists_every_method_in_registry_order():
    doc = lg.simulate.__doc__
    line = next(line for line in doc.splitlines() if line.strip().startswith("method:"))
    listed = [word.strip(" ,.") for word in doc[doc.index(line):].split(":", 1)[1]
              .split(".", 1)[0].replace("\n", " ").split(",")]
    assert listed == list(registry.METHODS)


@pytest.mark.parametrize("call", [
    lambda: lg.simulate(CART, "midpiont", t_end=1, h=1e-3),
    lambda: lg.ensemble(CART, "midpiont", t_end=1, h=1e-3),
    lambda: lg.Stepper(CART, "midpiont", h=1e-3),
])
def test_a_misspelt_method_gets_did_you_mean(call):
    with pytest.raises(SimulationError) as info:
        call()
    message = str(info.value)
    assert "did you mean 'midpoint'?" in message and "\n" not in message


def test_a_name_far_from_every_method_gets_the_list():
    message = registry.unknown_method("zzz")
    assert "did you mean" not in message and "rk4" in message


def test_simulate_without_t_end_names_it():
    with pytest.raises(SimulationError, match=r"^simulate: t_end .*required"):
        lg.simulate(CART, "midpoint", h=1e-3)


@pytest.mark.parametrize("missing, kwargs", [("t_end", dict(h=1e-3)), ("h", dict(t_end=1.0))])
def test_ensemble_without_t_end_or_h_names_it(missing, kwargs):
    with pytest.raises(SimulationError, match=rf"^ensemble: {missing} .*required"):
        lg.ensemble(CART, "rk4", **kwargs)


@pytest.mark.parametrize("command", ["simulate", "sweep"])
def test_cli_misspelt_method_is_one_line_with_did_you_mean(command, capsys):
    from lagrange_gen.cli.main import main
    extra = ["--grid", "k=1:2:2", "--h", "1e-3"] if command == "sweep" else []
    assert main([command, CART, "--method", "midpiont", "--t-end", "1", *extra]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("lagrange-gen: error: --method: unknown method 'midpiont'; did you "
                          "mean 'midpoint'?") and "\n" not in err
