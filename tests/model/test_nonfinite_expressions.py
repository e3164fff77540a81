"""A model expression holding sympy's infinities or NaN (zoo, oo, -oo, nan: a division by zero
such as x/0, log(0), 0*oo) is refused where it appears: at Model construction, or when a frozen
parameter's value makes one (derive(freeze=)), in one line naming the expression, the term and
the symbol; never generated into kernels that return NaN at run time."""

import pytest
import sympy as sp

from lagrange_gen import Model, coordinates, parameters
from lagrange_gen.cli.main import main
from lagrange_gen.derive import derive
from lagrange_gen.errors import GenerationError, ModelError

x, y = coordinates("x y")
m, k = parameters("m k", defaults=(1.0, 2.0))
T = m * (x.d**2 + y.d**2) / 2


def _refused(error, build):
    with pytest.raises(error) as info:
        build()
    message = str(info.value)
    assert "\n" not in message
    return message


@pytest.mark.parametrize("where, kwargs, term, symbol", [
    ("V", dict(V=sp.zoo * x), "zoo*x", "zoo"),
    ("V", dict(V=k * x**2 / 2 + sp.oo * y), "oo*y", "oo"),
    ("V", dict(V=k * x**2 / 2 + x / sp.Integer(0)), "zoo*x", "zoo"),
    ("T", dict(T=T + sp.nan * x.d**2), "nan", "nan"),
    ("force on y", dict(forces=[0, -sp.oo * y.d]), "-oo*y_dot", "-oo"),
    ("constraint 0", dict(constraints=[x**2 + y**2 - sp.log(0)]), "zoo", "zoo"),
])
def test_a_model_holding_an_infinity_or_nan_is_refused_at_construction(where, kwargs, term,
                                                                          symbol):
    args = dict(coords=[x, y], T=T, V=k * x**2 / 2)
    args.update(kwargs)
    message = _refused(ModelError, lambda: Model("bad", **args))
    assert message.startswith(f"model bad: {where} ")
    assert f"the term {term} " in message and f"holds {symbol} " in message


def test_a_finite_model_is_taken():
    model = Model("good", coords=[x, y], T=T, V=k * x**2 / 2 + sp.Min(x, 1) * y)
    assert model.name == "good"


def test_a_frozen_value_that_makes_an_infinity_is_refused_at_derivation():
    model = Model("spring", coords=[x, y], T=T, V=x**2 / (2 * k) + y**2)
    message = _refused(GenerationError, lambda: derive(model, freeze={"k": 0}))
    assert message.startswith("model spring: freezing k = 0 makes V ")
    assert "zoo" in message and "x**2" in message


def test_the_command_line_refuses_it_before_generating(tmp_path, capsys):
    model_file = tmp_path / "zoo_model.py"
    model_file.write_text(
        "import sympy as sp\n"
        "from lagrange_gen import Model, coordinates, parameters\n"
        "x = coordinates('x')\n"
        "m = parameters('m', defaults=(1.0,))\n"
        "model = Model('zoo_model', coords=[x], T=m * x.d**2 / 2, V=sp.zoo * x)\n")
    code = main(["simulate", str(model_file), "--method", "rk4", "--t-end", "0.01", "--h",
                 "1e-3", "--gen-dir", str(tmp_path / "gen")])
    err = capsys.readouterr().err
    assert code == 2 and len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert "V = zoo*x" in err and "holds zoo" in err
    assert not (tmp_path / "gen" / "zoo_model.py").exists()
