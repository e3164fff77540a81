"""PARAMS follow the model's own declarations: a generated file is byte-identical whether its
model is generated alone or after other models in the same process (issue 10 item 4).

Each run is a fresh subprocess. The "after" run first generates models from files and from the
Python API that declare the same parameter names (and others) in other orders with other
defaults, as a script or `lagrange-gen a.py b.py m.py` would; m.py takes g from a helper module
that the first model file already imported, so m.py's run no longer declares it."""

import re
import subprocess
import sys
import textwrap

import pytest

HEADER = "import sympy as sp\nfrom lagrange_gen import Model, coordinates, parameters\n"
FILES = {
    "shared.py": HEADER + 'g = parameters("g", defaults=(9.81,))\n',
    "a.py": HEADER + textwrap.dedent("""\
        from shared import g
        x = coordinates("x")
        c, m, k = parameters("c m k", defaults=(0.1, 2.0, 5.0))
        model = Model("a", coords=[x], T=m * x.d**2 / 2, V=k * x**2 / 2 + m * g * x,
                      dissipation=c * x.d**2 / 2)
    """),
    "b.py": HEADER + textwrap.dedent("""\
        th = coordinates("th")
        k, l, g, m = parameters("k l g m", defaults=(7.0, 3.0, 1.62, 4.0))
        model = Model("b", coords=[th], T=m * l**2 * th.d**2 / 2, V=-m * g * l * sp.cos(th) + k * th**2)
    """),
    "m.py": HEADER + textwrap.dedent("""\
        from shared import g
        x, th = coordinates("x theta")
        M, m, l, k = parameters("M m l k", defaults=(1.0, 0.5, 1.0, 10.0))
        T = (M + m) * x.d**2 / 2 + m * l * x.d * th.d * sp.cos(th) + m * l**2 * th.d**2 / 2
        model = Model("m", coords=[x, th], T=T, V=k * x**2 / 2 - m * g * l * sp.cos(th))
    """),
}

# The same cart pendulum built with the Python API (no file): its own declaration order is
# l, k, m, M, g and its own defaults.
API_MODEL = HEADER + textwrap.dedent("""\
    def api_model():
        x, th = coordinates("x theta")
        l, k, m, M, g = parameters("l k m M g", defaults=(0.8, 12.0, 0.3, 1.5, 9.8))
        T = (M + m) * x.d**2 / 2 + m * l * x.d * th.d * sp.cos(th) + m * l**2 * th.d**2 / 2
        return Model("api", coords=[x, th], T=T, V=k * x**2 / 2 - m * g * l * sp.cos(th))

    def others():
        y, z = coordinates("y z")
        g, M, k, m, q = parameters("g M k m q", defaults=(1.0, 2.0, 3.0, 4.0, 5.0))
        first = Model("other1", coords=[y], T=M * y.d**2 / 2, V=k * y**2 + m * g * y + q)
        m, l = parameters("m l", defaults=(6.0, 7.0))
        second = Model("other2", coords=[z], T=m * z.d**2 / 2, V=l * z**2)
        return [first, second]
""")

SCRIPT = textwrap.dedent("""\
    import sys
    from pathlib import Path
    from lagrange_gen.codegen import generate_model, generate_text
    from api_models import api_model, others
    out, mode = Path(sys.argv[1]), sys.argv[2]
    if mode == "after":
        for name in ("a.py", "b.py"):
            generate_model(name, out, methods=["rk4"])
        for model in others():
            generate_text(model, out, methods=["rk4"])
    generate_model("m.py", out, methods=["rk4"])
    text, _, target = generate_text(api_model(), out, methods=["rk4"])
    target.write_text(text)
""")


def _generate(tmp_path, mode):
    out = tmp_path / "gen"
    for stale in out.glob("*.py"):
        stale.unlink()
    run = subprocess.run([sys.executable, "-c", SCRIPT, str(out), mode], cwd=tmp_path,
                         capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr
    return {name: (out / name).read_bytes() for name in ("m.py", "api.py")}


@pytest.fixture(scope="module")
def both_runs(tmp_path_factory):
    tmp_path = tmp_path_factory.mktemp("order")
    for name, text in {**FILES, "api_models.py": API_MODEL}.items():
        (tmp_path / name).write_text(text)
    return _generate(tmp_path, "alone"), _generate(tmp_path, "after")


def _params(text):
    return re.search(r"^PARAMS = (.*)$", text.decode(), re.M).group(1), \
        re.search(r"^DEFAULTS = (.*)$", text.decode(), re.M).group(1)


def test_params_follow_the_models_own_declarations(both_runs):
    alone, _ = both_runs
    assert _params(alone["m.py"]) == ("('g', 'M', 'm', 'l', 'k')", "(9.81, 1.0, 0.5, 1.0, 10.0)")
    assert _params(alone["api.py"]) == ("('l', 'k', 'm', 'M', 'g')", "(0.8, 12.0, 0.3, 1.5, 9.8)")


@pytest.mark.parametrize("name", ["m.py", "api.py"])
def test_generated_file_is_byte_identical_alone_and_after_other_models(both_runs, name):
    alone, after = both_runs
    assert _params(after[name]) == _params(alone[name])
    assert after[name] == alone[name]


def test_two_declarations_of_one_name_in_one_model_are_refused():
    from lagrange_gen import Model, ModelError, coordinates, parameters
    x = coordinates("x")
    m_first = parameters("m", defaults=(1.0,))
    m_again, k = parameters("m k", defaults=(2.0, 3.0))
    with pytest.raises(ModelError, match=r"^model twice: parameter m is declared twice .*declare it once"):
        Model("twice", coords=[x], T=m_first * x.d**2 / 2, V=m_again * k * x**2)
    model = Model("once", coords=[x], T=m_again * x.d**2 / 2, V=k * x**2)
    assert [(p.name, d) for p, d in zip(model.params, model.defaults())] == [("m", 2.0), ("k", 3.0)]
