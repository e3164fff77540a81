"""lg.equations and `lagrange-gen equations` (issue 16, item 2), against the cart pendulum's
equations derived by hand from T = (M+m) x'^2/2 + m l x' th' cos th + m l^2 th'^2/2 and
V = k x^2/2 - m g l cos th:

    H = [[M + m, m l cos th], [m l cos th, m l^2]],  h = (-m l sin(th) th'^2, 0),
    g = (k x, m g l sin th),  Q = 0;
and the four-bar's constraints Phi from its model file, J = dPhi/dq by hand."""

from pathlib import Path

import sympy as sp

import lagrange_gen as lg
from lagrange_gen.cli.main import main

MODELS = Path(__file__).resolve().parents[2] / "models"
N = sp.Symbol


def _named(matrix):
    return matrix.xreplace({s: sp.Symbol(s.name) for s in matrix.free_symbols})


def test_cart_pendulum_equations_match_hand_derivation():
    eqs = lg.equations(MODELS / "cart_pendulum.py")
    M, m, l, k, g, x, th, thd = (N(s) for s in "M m l k g x theta theta_dot".split())
    H = sp.Matrix([[M + m, m * l * sp.cos(th)], [m * l * sp.cos(th), m * l**2]])
    h = sp.Matrix([-m * l * sp.sin(th) * thd**2, 0])
    gv = sp.Matrix([k * x, m * g * l * sp.sin(th)])
    for got, want in ((eqs.H, H), (eqs.h, h), (eqs.g, gv), (eqs.Q, sp.zeros(2, 1))):
        assert sp.simplify(_named(got) - want) == sp.zeros(*want.shape)
    assert eqs.Phi.shape == (0, 1) and eqs.J.shape[0] == 0
    assert [c.name for c in eqs.coords] == ["x", "theta"]


def test_constrained_equations_have_phi_j_gamma():
    eqs = lg.equations(MODELS / "four_bar.py")
    a, b, c, d, t1, t2, t3 = (N(s) for s in "a b c d th1 th2 th3".split())
    d1, d2, d3 = (N(s) for s in "th1_dot th2_dot th3_dot".split())
    phi = sp.Matrix([a * sp.cos(t1) + b * sp.cos(t2) - c * sp.cos(t3) - d,
                     a * sp.sin(t1) + b * sp.sin(t2) - c * sp.sin(t3)])
    J = phi.jacobian([t1, t2, t3])
    # gamma = -(d/dt J) qdot, by hand for these trigonometric rows
    gamma = sp.Matrix([a * sp.cos(t1) * d1**2 + b * sp.cos(t2) * d2**2 - c * sp.cos(t3) * d3**2,
                       a * sp.sin(t1) * d1**2 + b * sp.sin(t2) * d2**2 - c * sp.sin(t3) * d3**2])
    assert sp.simplify(_named(eqs.Phi) - phi) == sp.zeros(2, 1)
    assert sp.simplify(_named(eqs.J) - J) == sp.zeros(2, 3)
    assert sp.simplify(_named(eqs.gamma) - gamma) == sp.zeros(2, 1)


def test_cli_prints_the_equations_and_latex(capsys):
    assert main(["equations", str(MODELS / "cart_pendulum.py")]) == 0
    out = capsys.readouterr().out
    assert "H qddot + h + g = Q" in out and "H (mass matrix" in out and "g*l*m*sin(theta)" in out
    assert "Phi" not in out
    assert main(["equations", str(MODELS / "four_bar.py"), "--latex"]) == 0
    out = [line for line in capsys.readouterr().out.splitlines() if not line.startswith("%")]
    # the equation of motion, Phi = 0 and J qddot = gamma, matrices as bmatrix
    assert len(out) == 3 and out[1].endswith("= 0") and all("\\begin{bmatrix}" in s for s in out)


def test_cli_equations_of_a_family_and_a_bad_file(tmp_path, capsys):
    assert main(["equations", str(MODELS / "n_link_pendulum.py"), "--set", "n=2"]) == 0
    out = capsys.readouterr().out
    assert "model n_link_pendulum_2" in out and "th2" in out and "th3" not in out
    bad = tmp_path / "bad.py"
    bad.write_text("x = 1\n")
    assert main(["equations", str(bad)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "defines no Model" in err


def test_simplify_size_guard():
    """Entries above SIMPLIFY_MAX_OPS are left as derived; small ones are simplified; simplify=
    False leaves every entry alone."""
    from lagrange_gen.derive.equations import SIMPLIFY_MAX_OPS, _simplifier
    x = sp.Symbol("x")
    small = sp.sin(x)**2 + sp.cos(x)**2
    big = small + sum(sp.Symbol(f"a{i}") * x**i for i in range(SIMPLIFY_MAX_OPS))
    assert _simplifier(True)(small) == 1
    assert _simplifier(True)(big) == big and _simplifier(False)(small) == small
    raw = lg.equations(MODELS / "cart_pendulum.py", simplify=False)
    assert raw.H.shape == (2, 2)
