"""A generated module holds kernels and metadata only; its run_<method> / ensemble_<method> are
the library's (jit/specialized.py), written on first use beside the portable glue under the
module's KEY and the library version, and removed when the module's KEY changes."""

import shutil

import numpy as np
import pytest

import lagrange_gen as lg
from lagrange_gen.codegen import generate_model
from lagrange_gen.jit import portable, specialized
from lagrange_gen.run.loader import import_generated
from lg_test_support import MODELS_DIR, ROOT


@pytest.fixture
def own_cache(tmp_path, monkeypatch):
    """A portable folder of the test's own (the glue files it writes are looked at)."""
    folder = tmp_path / "portable"
    monkeypatch.setenv(portable.DIR_ENV, str(folder))
    return folder


def test_generated_files_hold_no_stepper_glue():
    """Every module in generated/: no function of a stepper's glue, SOURCES only what the
    kernels compile, so a changed stepper leaves it current."""
    for path in sorted((ROOT / "generated").glob("*.py")):
        text = path.read_text()
        assert "def run_" not in text and "def ensemble_" not in text, path.name
        assert "steppers/methods" not in text.split("SOURCES = ", 1)[1].split("\n", 1)[0], path.name


def test_glue_attributes_are_the_methods_of_the_module(generated, own_cache):
    mod = generated("cart_pendulum")
    assert "rk4" in mod.METHODS and "dop853" in mod.METHODS and "rattle" not in mod.METHODS
    assert hasattr(mod, "run_rk4") and hasattr(mod, "ensemble_rk4")
    assert hasattr(mod, "run_dop853")
    assert not hasattr(mod, "ensemble_dop853")        # adaptive: no ensemble glue
    assert not hasattr(mod, "run_rattle")             # a method the module does not run
    assert not hasattr(mod, "SOME_CONSTANT")
    with pytest.raises(AttributeError, match="has no attribute 'run_rattle'"):
        mod.run_rattle


def test_glue_file_names_the_key_and_library_version(tmp_path, own_cache):
    out = tmp_path / "gen"
    mod = import_generated(generate_model(MODELS_DIR / "damped_oscillator.py", out,
                                          methods=["rk4", "verlet"]).path)
    run = mod.run_rk4
    path = own_cache / portable.library_hash("rk4") / f"{specialized.glue_file_stem(mod)}.py"
    assert path.is_file() and mod.KEY[:specialized.KEY_DIGITS] in path.name
    text = path.read_text()
    assert f"_sys.modules[{mod.__name__!r}]" in text and "def run_rk4(" in text
    assert "def ensemble_rk4(" in text
    assert run.py_func.__code__.co_filename == str(path)
    assert mod.run_rk4 is run                          # kept in the module's namespace
    # the same text every time (numba's cache is keyed on the file's stamp)
    from lagrange_gen.codegen.glue import specialized_glue_source
    assert specialized_glue_source("rk4", mod.__name__, mod.KEY, portable.library_hash("rk4"),
                                   0, mod.N_EVENTS) == text


def test_a_new_key_removes_the_glue_of_the_earlier_one(tmp_path, own_cache):
    model = shutil.copy(MODELS_DIR / "damped_oscillator.py", tmp_path / "damped_oscillator.py")
    out = tmp_path / "gen"
    first = import_generated(generate_model(model, out, methods=["rk4"]).path)
    first.run_rk4
    folder = own_cache / portable.library_hash("rk4")
    old = folder / f"{specialized.glue_file_stem(first)}.py"
    cached = folder / "__pycache__" / f"{old.stem}.run_rk4-20.py311.nbi"   # as numba names it
    cached.parent.mkdir(exist_ok=True)
    cached.write_text("")
    unrelated = folder / "__pycache__" / "run_rk4.run_rk4-12.py311.nbi"
    unrelated.write_text("")
    text = model.read_text()
    assert "V=x**2 / (2 * c)" in text
    model.write_text(text.replace("V=x**2 / (2 * c)", "V=x**2 / (4 * c)"))
    second = import_generated(generate_model(model, out, methods=["rk4"]).path)
    assert second.KEY != first.KEY
    second.run_rk4
    new = folder / f"{specialized.glue_file_stem(second)}.py"
    assert new.is_file() and not old.exists() and not cached.exists() and unrelated.exists()


def test_specialized_and_portable_glue_agree(generated, own_cache):
    mod = generated("double_pendulum")
    runs = [lg.simulate(mod, "verlet", [0.3, -0.2], [0.0, 0.1], t_end=0.05, h=1e-3, jit=jit)
            for jit in ("specialized", "portable")]
    assert [r.jit for r in runs] == ["specialized", "portable"]
    np.testing.assert_array_equal(runs[0].q, runs[1].q)
