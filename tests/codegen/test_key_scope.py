"""A generated module runs only the methods that apply to its model, and its KEY depends only on
what it uses: the derived equations as emitted, the package sources its kernels compile, the
options. A comment in the model file or in any stepper changes nothing in it: the file stays
byte-identical and numba's on-disk cache (stamped with the generated file's mtime and size) is
used, not recompiled. A changed stepper gives the module's stepper glue (the library's,
jit/specialized.py) a new version instead. A real change of the equations is still seen by
``--check`` and ``load``; a change of what the kernels compile at import."""

import json
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import lagrange_gen
from lg_test_support import MODELS_DIR, ROOT
from lagrange_gen.cli.main import main
from lagrange_gen.codegen import keys
from lagrange_gen.jit import sources
from lagrange_gen.codegen import generate_model
from lagrange_gen.codegen.generated_files import check_generated
from lagrange_gen.errors import SimulationError, StaleModuleError
from lagrange_gen.run.loader import import_generated
from lagrange_gen.steppers.core.registry import CONSTRAINED_METHODS, METHODS, applicable_methods

# nonsmooth_euler is implicit Euler on a model without elements: simulate accepts it there.
UNCONSTRAINED = list(applicable_methods(0, 0))

# A fresh process loads the module from the model file (load() decides it is current), runs
# explicit_euler a few steps with the module's own (specialized) glue and prints numba's cache
# statistics of that glue.
RUN = """
import json, sys
import lagrange_gen as lg
mod = lg.load(sys.argv[1], out_dir=sys.argv[2])
lg.simulate(mod, "explicit_euler", [0.1, 0.3], [0.0, 0.0], t_end=0.01, h=0.001, jit="specialized")
stats = mod.run_explicit_euler.stats
print(json.dumps({"hits": sum(stats.cache_hits.values()), "misses": sum(stats.cache_misses.values())}))
"""


def _run_in_fresh_process(model, out):
    done = subprocess.run([sys.executable, "-c", RUN, str(model), str(out)], capture_output=True,
                          text=True, timeout=600, cwd=ROOT)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout.strip().splitlines()[-1])


def _cache_stamps(out):
    """{numba cache file: mtime_ns} of the generated modules in ``out``."""
    return {p.name: p.stat().st_mtime_ns for p in (out / "__pycache__").glob("*.nb[ic]")}


@pytest.fixture(scope="module")
def cart(tmp_path_factory):
    """cart_pendulum copied to a tmp directory, generated into out/ (default methods)."""
    where = tmp_path_factory.mktemp("scope")
    model = shutil.copy(MODELS_DIR / "cart_pendulum.py", where / "cart_pendulum.py")
    result = generate_model(model, where / "out")
    return Path(model), where / "out", result.path


def test_default_glue_is_the_methods_that_apply(cart, tmp_path):
    _, _, target = cart
    assert list(import_generated(target).METHODS) == UNCONSTRAINED
    four_bar = import_generated(generate_model(MODELS_DIR / "four_bar.py", tmp_path).path)
    assert list(four_bar.METHODS) == list(CONSTRAINED_METHODS)
    prandtl = import_generated(generate_model(MODELS_DIR / "prandtl.py", tmp_path).path)
    assert list(prandtl.METHODS) == ["nonsmooth_euler"]
    # as in simulate, implicit_euler runs as nonsmooth_euler on a model with elements
    routed = generate_model(MODELS_DIR / "prandtl.py", tmp_path / "r", methods=["implicit_euler"])
    assert "METHODS = ('nonsmooth_euler',)" in routed.path.read_text()


def test_an_inapplicable_method_is_refused_in_one_line(cart, tmp_path, capsys):
    model, _, _ = cart
    assert main([str(model), "-o", str(tmp_path), "--methods", "verlet,rattle"]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "rattle" in err and "models with constraints" in err, err
    assert not (tmp_path / "cart_pendulum.py").exists()
    # simulate (through load) does not add it either: it refuses it with its own message
    with pytest.raises(SimulationError, match="'rattle' is for models with constraints"):
        lagrange_gen.simulate(model, "rattle", [0.1, 0.3], t_end=0.01, h=0.001, out_dir=tmp_path)
    assert "rattle" not in import_generated(tmp_path / "cart_pendulum.py").METHODS


def test_comment_in_the_model_file_changes_nothing_and_nothing_recompiles(cart):
    model, out, target = cart
    first = _run_in_fresh_process(model, out)
    assert first["misses"] >= 1                          # compiled (and cached) here
    before, stamp, cache = target.read_bytes(), target.stat().st_mtime_ns, _cache_stamps(out)
    text = model.read_text()
    model.write_text("# a comment added to the model file\n" + text.replace('"""', '"""Edited. ', 1))
    generate_model(model, out)
    assert target.read_bytes() == before and target.stat().st_mtime_ns == stamp
    assert check_generated(model, out)[1] is None
    again = _run_in_fresh_process(model, out)           # load() re-derives: current, not rewritten
    assert again == {"hits": 1, "misses": 0}, again
    assert target.stat().st_mtime_ns == stamp and _cache_stamps(out) == cache


@pytest.fixture
def package_copy(tmp_path, monkeypatch):
    """A copy of the lagrange_gen sources whose files the generator hashes and the import check
    reads (keys._PACKAGE, sources._PACKAGE point at it); the code that runs stays the installed
    one, so a test can edit a stepper's text without touching the package."""
    copy = tmp_path / "lagrange_gen"
    shutil.copytree(Path(lagrange_gen.__file__).parent, copy,
                    ignore=shutil.ignore_patterns("__pycache__", "*.nb[ic]"))
    monkeypatch.setattr(keys, "_PACKAGE", copy)
    monkeypatch.setattr(sources, "_PACKAGE", copy)
    return copy


def _add_comment(path):
    path.write_text(path.read_text() + "\n# a comment added by test_key_scope\n")


def test_comment_in_a_stepper_leaves_the_module_current_and_versions_its_glue(cart, package_copy):
    """The module does not go stale when a stepper changes, glued or not; the library version of
    its glue (the folder its glue file is written to) changes instead, so numba compiles that
    glue again and nothing else."""
    from lagrange_gen.jit import portable
    model, out, target = cart
    before, stamp = target.read_bytes(), target.stat().st_mtime_ns
    generate_model(model, out)                 # same text from the copy: hashes are of bytes
    assert target.read_bytes() == before
    versions = {m: portable.library_hash(m) for m in ("rk4", "midpoint")}
    _add_comment(package_copy / "steppers" / "core" / "options.py")       # shared by every stepper
    _add_comment(package_copy / "steppers" / "methods" / "rattle.py")     # not a method of the cart
    generate_model(model, out)
    assert target.read_bytes() == before and target.stat().st_mtime_ns == stamp
    assert check_generated(model, out)[1] is None
    keys.check_current(target, *(import_generated(target).__dict__[k] for k in
                                 ("KEY", "SOURCES", "MODEL_PATH", "OPTIONS", "TEXT_SHA")))
    assert all(portable.library_hash(m) != v for m, v in versions.items())


def test_comment_in_what_the_kernels_compile_makes_the_module_stale(cart, package_copy, tmp_path):
    model, _, target = cart
    out = tmp_path / "own"
    first = generate_model(model, out)
    mod = import_generated(first.path)
    fields = [mod.KEY, mod.SOURCES, mod.MODEL_PATH, mod.OPTIONS, mod.TEXT_SHA]
    assert sorted(mod.SOURCES) == ["steppers/core/linalg.py", "steppers/core/status.py"]
    _add_comment(package_copy / "steppers" / "core" / "linalg.py")       # the kernels' Cholesky
    with pytest.raises(StaleModuleError, match=r"steppers/core/linalg\.py changed since generation.*lagrange-gen"):
        keys.check_current(first.path, *fields)
    assert "kernel sources changed: steppers/core/linalg.py" in check_generated(model, out)[1]
    second = generate_model(model, out)
    assert second.written and second.key != first.key


def test_a_real_change_of_the_equations_is_seen(tmp_path, capsys):
    model = shutil.copy(MODELS_DIR / "cart_pendulum.py", tmp_path / "cart_pendulum.py")
    out = tmp_path / "out"
    first = generate_model(model, out)
    text, potential = Path(model).read_text(), "V = k * x**2 / 2 - m * g * l * sp.cos(th)"
    assert potential in text
    Path(model).write_text(text.replace(potential, potential.replace("m * g", "2 * m * g")))
    assert main(["--check", str(model), "-o", str(out)]) == 1
    assert "its equations changed" in capsys.readouterr().out
    mod = lagrange_gen.load(model, out_dir=out)
    assert mod.KEY != first.key
    assert main(["--check", str(model), "-o", str(out)]) == 0


def test_a_module_of_the_older_format_is_stale_with_the_default_command(tmp_path):
    """Modules written before SOURCES call keys.check_fresh: stale, and the command does not
    repeat their 13 methods (most do not apply any more)."""
    everything = {"build": {}, "methods": list(METHODS)}
    with pytest.raises(StaleModuleError, match=r"older lagrange-gen: run lagrange-gen \S*cart_pendulum\.py -o \S+$"):
        keys.check_fresh(tmp_path / "out" / "cart_pendulum.py", "0", "0", "0", "../cart_pendulum.py",
                         everything, "0")
    model = shutil.copy(MODELS_DIR / "cart_pendulum.py", tmp_path / "cart_pendulum.py")
    target = generate_model(model, tmp_path / "out").path
    target.write_text("".join(line for line in target.read_text().splitlines(keepends=True)
                              if not line.startswith("SOURCES = ")))
    assert check_generated(model, tmp_path / "out")[1] == "stale (generated by an older lagrange-gen)"
