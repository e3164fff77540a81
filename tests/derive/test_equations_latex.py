"""`lagrange-gen equations --latex` and Equations.latex(): coordinates and velocities as a
reader writes them (th1 -> \\theta_{1}, th1_dot -> \\dot{\\theta}_{1}), and the assembled
equation H qddot + h + g = Q in matrix form, compared with LaTeX written by hand; large
models print their shared subexpressions once."""

import sympy as sp

import lagrange_gen as lg
from lagrange_gen import Model, coordinates, parameters
from lagrange_gen.derive import equations as equations_module
from lagrange_gen.derive.equations import latex_symbol_names


def _coupled():
    th1, th2 = coordinates("th1 th2")
    k, b = parameters("k b", defaults=1.0)
    return Model("coupled", coords=[th1, th2], T=(th1.d**2 + th2.d**2) / 2,
                 V=k * (th1 - th2)**2 / 2, dissipation=b * th2.d**2 / 2)


def test_symbol_names_greek_subscripts_and_dots():
    th1, phi, x_c, q12, theta_2 = coordinates("th1 phi x_c q12 theta_2")
    names = latex_symbol_names([th1, phi, x_c, q12, theta_2])
    assert names[th1] == r"\theta_{1}" and names[th1.d] == r"\dot{\theta}_{1}"
    assert names[phi] == r"\phi" and names[phi.d] == r"\dot{\phi}"
    assert names[x_c] == r"x_{c}" and names[x_c.d] == r"\dot{x}_{c}"
    assert names[q12] == r"q_{12}" and names[q12.d] == r"\dot{q}_{12}"
    assert names[theta_2.d] == r"\dot{\theta}_{2}"


def test_the_assembled_equation_of_a_small_model_is_the_hand_written_one():
    text = lg.equations(_coupled()).latex()
    lines = [line for line in text.splitlines() if not line.startswith("%")]
    assert lines == [
        r"\begin{bmatrix} 1 & 0 \\ 0 & 1 \end{bmatrix}"
        r" \begin{bmatrix} \ddot{\theta}_{1} \\ \ddot{\theta}_{2} \end{bmatrix}"
        r" + \begin{bmatrix} k \left(\theta_{1} - \theta_{2}\right) \\"
        r" k \left(- \theta_{1} + \theta_{2}\right) \end{bmatrix}"
        r" = \begin{bmatrix} 0 \\ - b \dot{\theta}_{2} \end{bmatrix}"]
    assert "th_{" not in text and "dot}" not in text


def test_a_constrained_model_adds_the_multipliers_and_the_constraint_rows():
    x, y = coordinates("x y")
    L = parameters("L", defaults=1.0)
    model = Model("circle", coords=[x, y], T=(x.d**2 + y.d**2) / 2,
                  constraints=[x**2 + y**2 - L**2])
    lines = [s for s in lg.equations(model).latex().splitlines() if not s.startswith("%")]
    # h, g and Q are zero: left out
    assert lines[0] == (r"\begin{bmatrix} 1 & 0 \\ 0 & 1 \end{bmatrix}"
                        r" \begin{bmatrix} \ddot{x} \\ \ddot{y} \end{bmatrix}"
                        r" = \begin{bmatrix} 2 x \\ 2 y \end{bmatrix}"
                        r" \begin{bmatrix} \lambda_{1} \end{bmatrix}")
    assert lines[1] == r"\begin{bmatrix} x^{2} + y^{2} - L^{2} \end{bmatrix} = 0"
    assert lines[2] == (r"\begin{bmatrix} 2 x & 2 y \end{bmatrix}"
                        r" \begin{bmatrix} \ddot{x} \\ \ddot{y} \end{bmatrix}"
                        r" = \begin{bmatrix} - 2 \dot{x}^{2} - 2 \dot{y}^{2} \end{bmatrix}")


def test_large_entries_are_printed_through_shared_subexpressions(monkeypatch):
    monkeypatch.setattr(equations_module, "CSE_MIN_OPS", 1)
    th1, th2 = coordinates("th1 th2")
    l = parameters("l", defaults=1.0)
    c = sp.cos(th1 - th2)
    T = l**2 * (th1.d**2 + th2.d**2 + 2 * c * th1.d * th2.d) / 2
    model = Model("shared", coords=[th1, th2], T=T, V=-l * sp.cos(th1) - l * sp.cos(th2))
    text = lg.equations(model, simplify=False).latex()
    where = [s for s in text.splitlines() if s.startswith(r"\xi_{")]
    assert where and r"\xi_{0} = " in where[0]
    assert "% where" in text
