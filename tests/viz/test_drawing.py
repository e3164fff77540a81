"""Model(draw=Drawing(...)): the drawn points equal their closed forms, bad drawings are refused
in one line, and a drawing leaves the generated module unchanged."""

import shutil

import numpy as np
import pytest
import sympy as sp

from lagrange_gen import Drawing, Model, ModelError, coordinates, parameters
from lagrange_gen.codegen import generate_model
from lagrange_gen.model.drawing import positions_function
from lagrange_gen.model.model_file import load_model
from tests.conftest import MODELS_DIR

rng = np.random.default_rng(7)


def positions(stem, q, **build):
    model = load_model(MODELS_DIR / f"{stem}.py", **build)
    return positions_function(model)(q, model.defaults(), np.zeros(len(q))), model


def test_double_pendulum_points_are_the_bobs():
    q = rng.uniform(-4, 4, (5, 2))
    xyz, model = positions("double_pendulum", q)
    assert model.draw.names == ("pivot", "m1", "m2") and xyz.shape == (5, 3, 2)
    l1 = l2 = 1.0
    m1 = np.column_stack([l1 * np.sin(q[:, 0]), -l1 * np.cos(q[:, 0])])
    m2 = m1 + np.column_stack([l2 * np.sin(q[:, 1]), -l2 * np.cos(q[:, 1])])
    np.testing.assert_allclose(xyz[:, 0], 0.0)
    np.testing.assert_allclose(xyz[:, 1], m1, rtol=0, atol=1e-15)
    np.testing.assert_allclose(xyz[:, 2], m2, rtol=0, atol=1e-15)


def test_n_link_points_follow_the_build_option():
    q = rng.uniform(-3, 3, (4, 5))
    xyz, model = positions("n_link_pendulum", q, n=5)
    assert xyz.shape == (4, 6, 2) and len(model.draw.segments) == 5
    tip = np.column_stack([np.sin(q).sum(axis=1), -np.cos(q).sum(axis=1)])
    np.testing.assert_allclose(xyz[:, -1], tip, rtol=0, atol=1e-14)


def test_spherical_pendulum_is_drawn_in_3d():
    q = rng.uniform(-3, 3, (6, 2))
    xyz, _ = positions("spherical_pendulum", q)
    bob = np.column_stack([np.sin(q[:, 0]) * np.cos(q[:, 1]), np.sin(q[:, 0]) * np.sin(q[:, 1]),
                           np.cos(q[:, 0])])
    assert xyz.shape == (6, 2, 3)
    np.testing.assert_allclose(xyz[:, 1], bob, rtol=0, atol=1e-15)


def test_heavy_top_axis_and_rim():
    """The symmetry axis e3 (centre at l e3, polar angle theta, azimuth phi - pi/2) and the rim
    point l/2 from the centre, perpendicular to the axis, turning with psi."""
    q = rng.uniform(-3, 3, (6, 3))
    xyz, _ = positions("heavy_top", q)
    l = 0.5
    tip, centre, rim = xyz[:, 0], xyz[:, 1], xyz[:, 2]
    np.testing.assert_allclose(tip, 0.0)
    np.testing.assert_allclose(centre[:, 2], l * np.cos(q[:, 0]), atol=1e-15)
    np.testing.assert_allclose(np.hypot(centre[:, 0], centre[:, 1]), l * np.abs(np.sin(q[:, 0])),
                               atol=1e-15)
    spoke = rim - centre
    np.testing.assert_allclose(np.linalg.norm(spoke, axis=1), l / 2, atol=1e-15)
    np.testing.assert_allclose(np.einsum("ij,ij->i", spoke, centre), 0.0, atol=1e-15)
    # at theta = 0 the body x axis is turned by phi + psi from the space x axis
    top, _ = positions("heavy_top", np.array([[0.0, 0.3, 0.4]]))
    np.testing.assert_allclose(top[0, 2], [l / 2 * np.cos(0.7), l / 2 * np.sin(0.7), l], atol=1e-15)


def test_four_bar_closes_on_a_consistent_state():
    """C drawn from the coupler and from the rocker coincide where Phi(q) = 0."""
    a, b, c, d = 1.0, 3.0, 2.5, 3.0
    th1 = 0.4
    B = np.array([a * np.cos(th1), a * np.sin(th1)])
    D = np.array([d, 0.0])
    r = np.linalg.norm(D - B)               # triangle B C D: solve for C by the law of cosines
    base = np.arctan2(*(D - B)[::-1])
    gamma = np.arccos((b**2 + r**2 - c**2) / (2 * b * r))
    th2 = base + gamma
    C = B + b * np.array([np.cos(th2), np.sin(th2)])
    th3 = np.arctan2(C[1], C[0] - d)
    xyz, _ = positions("four_bar", np.array([[th1, th2, th3]]))
    names = ("A", "B", "C", "C_rocker", "D")
    p = dict(zip(names, xyz[0]))
    np.testing.assert_allclose(p["B"], B, atol=1e-15)
    np.testing.assert_allclose(p["C"], C, atol=1e-14)
    np.testing.assert_allclose(p["C_rocker"], C, atol=1e-14)
    np.testing.assert_allclose(p["D"], D)


def test_time_and_cart_pendulum():
    x, th = coordinates("x theta")
    l, g = parameters("l g", defaults=(2.0, 9.81))
    from lagrange_gen import t
    model = Model("drawn", coords=[x, th], T=(x.d**2 + l**2 * th.d**2) / 2, V=-g * l * sp.cos(th),
                  draw=Drawing({"cart": (x + t, 0), "bob": (x + l * sp.sin(th), -l * sp.cos(th))},
                               [("cart", "bob")]))
    xyz = positions_function(model)(np.array([[1.0, 0.5]]), [3.0, 9.81], np.array([0.25]))
    np.testing.assert_allclose(xyz[0], [[1.25, 0.0], [1 + 3 * np.sin(0.5), -3 * np.cos(0.5)]])


def _model(draw):
    x, th = coordinates("x theta")
    l = parameters("l", defaults=(1.0,))
    return Model("bad", coords=[x, th], T=(x.d**2 + th.d**2) / 2, V=l * sp.cos(th), draw=draw)


@pytest.mark.parametrize("draw, message", [
    ("points", r"model bad: draw must be a lagrange_gen.Drawing\(points=..., segments=...\), got str"),
    (lambda x, th: Drawing({}), "model bad: draw: points must be a non-empty dict"),
    (lambda x, th: Drawing({"p": (x, sp.Symbol("w"))}), r"model bad: draw: point p uses w, which is neither"),
    (lambda x, th: Drawing({"p": (x.d, 0)}), r"point p uses x_dot, which is neither .*velocities are not drawn"),
    (lambda x, th: Drawing({"p": (x, 0, 0, 1)}), r"point p must be 2 or 3 coordinates"),
    (lambda x, th: Drawing({"p": (x, 0), "r": (th, 0, 1)}), r"points mix 2D and 3D \(p: 2D, r: 3D\)"),
    (lambda x, th: Drawing({"p": (x, 0)}, [("p", "q")]), r"segment \('p', 'q'\) names point 'q', which is not one of the points \(p\)"),
    (lambda x, th: Drawing({"p": (x, 0)}, ["pq"]), r"segment 'pq' must be a pair"),
    (lambda x, th: Drawing({"no good": (x, 0)}), r"point name 'no good' is not a valid Python identifier"),
])
def test_bad_drawings_are_one_line(draw, message):
    x, th = coordinates("x theta")
    with pytest.raises(ModelError, match=message) as info:
        _model(draw(x, th) if callable(draw) else draw)
    assert "\n" not in str(info.value)


def test_a_model_without_drawing_says_how_to_declare_one():
    with pytest.raises(ModelError, match=r"model bad declares nothing to draw: give Model\(\.\.\., draw="):
        positions_function(_model(None))


def test_drawing_leaves_the_generated_module_unchanged(tmp_path):
    texts = []
    for variant, source in (("with", (MODELS_DIR / "cart_pendulum.py").read_text()),
                            ("without", None)):
        models = tmp_path / variant / "models"
        models.mkdir(parents=True)
        if source is None:
            source = texts[0][1]
            start = source.index(",\n              draw=Drawing(")
            source = source[:start] + ")\n"
        (models / "cart_pendulum.py").write_text(source)
        result = generate_model(models / "cart_pendulum.py", tmp_path / variant / "generated",
                                methods=["rk4"])
        texts.append((result.path.read_text(), source))
    assert "draw=" in texts[0][1] and "draw=" not in texts[1][1]
    assert load_model(tmp_path / "without" / "models" / "cart_pendulum.py").draw is None
    assert texts[0][0] == texts[1][0]
