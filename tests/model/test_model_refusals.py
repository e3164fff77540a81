"""Silent paths closed at the model: what the tool used to accept and answer wrongly is refused
with one line naming the symbol, term or parameter (issue 10 item 4, issue 11 rows)."""

import math
import re
import textwrap

import pytest
import sympy as sp

from lagrange_gen import Model, ModelError, PointForce, SaintVenant, coordinates, parameters
from lagrange_gen.cli.main import main


def _refusal(build):
    """The one-line ModelError message that ``build()`` raises."""
    with pytest.raises(ModelError) as info:
        build()
    message = str(info.value)
    assert "\n" not in message, message
    return message


# -- V must not depend on velocities ------------------------------------------------------------

def test_velocity_dependent_potential_is_refused_naming_the_velocity():
    x, y = coordinates("x y")
    message = _refusal(lambda: Model("vdep", coords=[x, y], T=(x.d**2 + y.d**2) / 2,
                                     V=x**2 / 2 + y.d * x))
    assert re.search(r"model vdep: V depends on the velocity y_dot \(y\.d\)", message), message
    assert "x_dot" not in message
    assert "belong in T or in forces" in message


# -- Rayleigh dissipation: quadratic (or higher) in the velocities --------------------------------

@pytest.mark.parametrize("term, why", [
    ("c*x**2/2", "does not depend on any velocity"),
    ("c*x*x_dot", "is linear in the velocities"),
    ("c*sin(x_dot)", "is linear in the velocities"),
    ("c*(1 + x_dot**2)", "is not zero at rest"),
])
def test_dissipation_term_without_a_quadratic_velocity_dependence_is_refused(term, why):
    x, y = coordinates("x y")
    c = parameters("c", defaults=(0.5,))
    bad = sp.sympify(term, locals={"x": x, "x_dot": x.d, "c": c})
    D = c * (x.d - y.d) ** 2 / 2 + bad                # a good dashpot plus the bad term
    message = _refusal(lambda: Model("leaky", coords=[x, y], T=(x.d**2 + y.d**2) / 2, dissipation=D))
    assert f"model leaky: dissipation term {bad}" in message, message
    assert why in message, message


def test_dissipation_of_degree_two_and_higher_is_accepted():
    x, y = coordinates("x y")
    c = parameters("c", defaults=(0.5,))
    for D in (c * (x.d - y.d) ** 2 / 2, c * sp.Abs(x.d) ** 3 / 3 + c * x**2 * y.d**2):
        model = Model("fine", coords=[x, y], T=(x.d**2 + y.d**2) / 2, dissipation=D)
        assert model.dissipation == D


# -- parameter defaults must be finite ----------------------------------------------------------

@pytest.mark.parametrize("value", [math.nan, math.inf, -math.inf, "abc"])
def test_non_finite_parameter_default_is_refused_naming_the_parameter(value):
    message = _refusal(lambda: parameters("m k", defaults=(1.0, value)))
    assert re.search(r"parameter k: default .* is not a finite number", message), message
    message = _refusal(lambda: parameters("m k", defaults={"k": value}))
    assert "parameter k:" in message


def test_nan_default_in_a_model_file_is_one_line_naming_file_and_parameter(tmp_path, capsys):
    path = tmp_path / "nan_default.py"
    path.write_text(textwrap.dedent("""\
        from lagrange_gen import Model, coordinates, parameters
        x = coordinates("x")
        m, k = parameters("m k", defaults=(1.0, float("nan")))
        model = Model("nan_default", coords=[x], T=m * x.d**2 / 2, V=k * x**2 / 2)
    """))
    assert main([str(path), "-o", str(tmp_path / "out")]) != 0
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "Traceback" not in err, err
    assert str(path) in err and "parameter k" in err and "nan" in err, err
    assert not (tmp_path / "out" / "nan_default.py").exists()


# -- every user expression must be a scalar -----------------------------------------------------

def _matrix_cases():
    x = coordinates("x")
    k = parameters("k", defaults=(1.0,))
    T, M = x.d**2 / 2, sp.Matrix([x, 1])
    return {
        "T": lambda: Model("mat", [x], T=sp.Matrix([T])),
        "V": lambda: Model("mat", [x], T=T, V=M),
        "dissipation": lambda: Model("mat", [x], T=T, dissipation=sp.Matrix([[x.d**2]])),
        "force on x": lambda: Model("mat", [x], T=T, forces={x: M}),
        "force 0": lambda: Model("mat", [x], T=T, forces=[M]),
        "forces": lambda: Model("mat", [x], T=T, forces=x),
        "constraint 0": lambda: Model("mat", [x], T=T, constraints=[M]),
        "constraints": lambda: Model("mat", [x], T=T, constraints=x),
        "point of PointForce 0": lambda: Model("mat", [x], T=T, forces=[PointForce([M, 0], [1, 0])]),
        "force of PointForce 0": lambda: Model("mat", [x], T=T, forces=[PointForce([x, 0], [M, 0])]),
        "strain of element saint_venant_0": lambda: Model(
            "mat", [x], T=T, elements=[SaintVenant(strain=M, stiffness=k, threshold=k)]),
        "coefficient of element saint_venant_0": lambda: Model(
            "mat", [x], T=T, elements=[SaintVenant(strain=x, stiffness=sp.Matrix([k]), threshold=k)]),
    }


@pytest.mark.parametrize("where", sorted(_matrix_cases()))
def test_non_scalar_expression_is_refused_naming_the_entry_point(where):
    message = _refusal(_matrix_cases()[where])
    assert message.startswith(f"model mat: {where} "), message
    assert "scalar" in message or "sequence" in message, message


def test_matrix_T_in_a_model_file_is_one_line_naming_T(tmp_path, capsys):
    path = tmp_path / "matrix_t.py"
    path.write_text(textwrap.dedent("""\
        import sympy as sp
        from lagrange_gen import Model, coordinates
        x, y = coordinates("x y")
        model = Model("matrix_t", coords=[x, y], T=sp.Matrix([x.d**2 / 2, y.d**2 / 2]))
    """))
    assert main([str(path), "-o", str(tmp_path / "out")]) != 0
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "Traceback" not in err, err
    assert re.search(r"matrix_t\.py: model matrix_t: T is a 2 x 1 matrix, not a scalar", err), err


# -- a sign error in T names the coordinates of the negative direction ---------------------------

def test_indefinite_T_names_the_coordinates_of_the_weakest_direction(tmp_path, capsys):
    """H = [[2, 0.3, 0], [0.3, -1, 0], [0, 0, 0.01]]: the sign error is in y's term. The smallest
    diagonal entry in absolute value is z's (0.01), but z is fine: the eigenvector of the
    smallest eigenvalue (-1.03) lies along y (components 0.1 in x, 0.99 in y, 0 in z)."""
    path = tmp_path / "sign_error.py"
    path.write_text(textwrap.dedent("""\
        from lagrange_gen import Model, coordinates
        x, y, z = coordinates("x y z")
        T = (2 * x.d**2 + 0.6 * x.d * y.d - y.d**2 + 0.01 * z.d**2) / 2
        model = Model("sign_error", coords=[x, y, z], T=T)
    """))
    assert main([str(path), "-o", str(tmp_path / "out")]) != 0
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "Traceback" not in err, err
    assert "not positive definite" in err, err
    named = re.search(r"check the terms in (.*)\)", err).group(1)
    assert named == "y.d", err
