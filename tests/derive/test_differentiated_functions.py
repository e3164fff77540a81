"""Every function sympy produces when differentiating what users write (Heaviside -> DiracDelta,
Abs -> sign, Min/Max -> Heaviside, Piecewise, floor) is printed and evaluated, or refused in
one line naming the expression: never a NameError or a traceback (issue 34, item 4). Through the
command line, as a user runs it: generation, the numeric checks of the derivation, the kernels."""

import pytest

from lagrange_gen.cli.main import main

HEADER = '''import sympy as sp
from lagrange_gen import Model, coordinates, parameters, t
x, x0 = coordinates("x x0")
m, k, a = parameters("m k a", defaults=(1.0, 1.0, 0.5))
'''

#: name: (the model's Model(...) line, whether it must run: True, or the words of its refusal)
CASES = {
    "heaviside_prescribed": ("Model('case', coords=[x], T=m * (x.d + x0.d)**2 / 2, "
                             "V=k * (x - x0)**2 / 2, prescribed={x0: a * sp.Heaviside(t - 1)})", True),
    "heaviside_in_v": ("Model('case', coords=[x], T=m * x.d**2 / 2, "
                       "V=k * x**2 / 2 + a * sp.Heaviside(x - 2) * (x - 2)**2)", True),
    "abs_in_v": ("Model('case', coords=[x], T=m * x.d**2 / 2, V=k * sp.Abs(x)**3 / 3)", True),
    "abs_drag": ("Model('case', coords=[x], T=m * x.d**2 / 2, V=k * x**2 / 2, "
                 "dissipation=a * sp.Abs(x.d)**3 / 3)", True),
    "min_max": ("Model('case', coords=[x], T=m * x.d**2 / 2, "
                "V=k * sp.Max(x, 0)**2 / 2 + k * sp.Min(x, 0)**2)", True),
    "piecewise": ("Model('case', coords=[x], T=m * x.d**2 / 2, "
                  "V=sp.Piecewise((k * x**2 / 2, x > 0), (k * x**2, True)))", True),
    "floor": ("Model('case', coords=[x], T=m * x.d**2 / 2, V=k * x**2 / 2 + a * sp.floor(x))", True),
    "sign_prescribed": ("Model('case', coords=[x], T=m * (x.d + x0.d)**2 / 2, V=k * x**2 / 2, "
                        "prescribed={x0: a * sp.sign(t - 1) * (t - 1)})", True),
    "frac": ("Model('case', coords=[x], T=m * x.d**2 / 2, V=k * x**2 / 2 + a * sp.frac(x))", True),
    "mod": ("Model('case', coords=[x], T=m * x.d**2 / 2, V=k * x**2 / 2 + a * sp.Mod(2 * x, 3))", True),
    "zeta_refused": ("Model('case', coords=[x], T=m * x.d**2 / 2, V=k * x**2 / 2 + a * sp.zeta(x))",
                     ("zeta", "unevaluated")),
    "undefined_function": ("Model('case', coords=[x], T=m * x.d**2 / 2, "
                           "V=sp.Function('f')(x))", ("f(x)",)),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_function_is_handled_or_refused_in_one_line(tmp_path, monkeypatch, capsys, case):
    line, outcome = CASES[case]
    monkeypatch.chdir(tmp_path)
    (tmp_path / "case.py").write_text(HEADER + f"model = {line}\n")
    code = main(["simulate", "case.py", "--gen-dir", "gen", "--method", "rk4", "--q0", "0.5",
                 "--t-end", "2", "--h", "0.01"])
    out, err = capsys.readouterr()
    assert "Traceback" not in err and "internal error" not in err, err
    if outcome is True:
        assert code == 0, err
        assert "final q = [" in out and "nan" not in out.split("final q")[1], out
    else:
        lines = [ln for ln in err.splitlines() if "error" in ln]
        assert code != 0 and len(lines) == 1, err
        for word in outcome:
            assert word in lines[0], err


def test_frac_and_its_derivative_are_printed_as_sympy_means_them(tmp_path):
    """a*frac(x) was printed ``a*x % 1``, i.e. (a x) mod 1; and symengine, running the CSE,
    dropped the unevaluated Derivative(frac(x), x) from the force without a word."""
    import numpy as np
    import sympy as sp
    from lagrange_gen import Model, coordinates, parameters
    from lagrange_gen.codegen import generate_text
    from lagrange_gen.run.loader import import_generated
    x = coordinates("x")
    k, a = parameters("k a", defaults=(2.0, 0.5))
    model = Model("fr", coords=[x], T=x.d**2 / 2, V=k * x**2 / 2 + a * sp.frac(x))
    model.source_path = str(tmp_path / "fr.py")
    text, _, target = generate_text(model, tmp_path, methods=["rk4"])
    target.write_text(text)
    mod = import_generated(target)
    q, v, p = np.array([2.3]), np.array([0.0]), np.array([2.0, 0.5])
    assert mod.energy(q, v, 0.0, p) == pytest.approx(2.0 * 2.3**2 / 2 + 0.5 * 0.3)
    H, rhs = np.empty((1, 1)), np.empty(1)
    mod.dynamics(q, v, 0.0, p, H, rhs)
    assert rhs[0] == pytest.approx(-2.0 * 2.3 - 0.5)


def test_a_point_force_at_a_point_with_floor_builds_and_its_jump_does_no_work():
    """A point force's virtual work differentiates the point: d floor(x)/dx stays unevaluated in
    the Model's generalized force, and derive sets it to 0 (the model was refused as 'an
    undefined function or derivative' by the harness's thorough draws)."""
    import sympy as sp

    from lagrange_gen import Model, PointForce, coordinates
    from lagrange_gen.derive import derive
    from lagrange_gen.derive.kinks import settle_derivatives
    x = coordinates("x")
    model = Model("floor_point", coords=[x], T=x.d**2 / 2,
                  forces=[PointForce(point=(x / 2 + sp.floor(x),), force=(sp.Integer(3),))])
    Q = settle_derivatives(derive(model).Q[0])
    assert sp.simplify(Q - sp.Rational(3, 2)) == 0
