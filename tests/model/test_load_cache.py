"""lg.load(model_file) does not run a model file whose module is generated and current (issue 28):
the model file's text, build options and the generator's sources key what it gave. Each model
file here counts its runs in a file beside it, so the tests see whether it ran."""

import subprocess
import sys
import textwrap

from lagrange_gen import load
from lagrange_gen.codegen import model_cache

SPRING = textwrap.dedent("""\
    from pathlib import Path
    from lagrange_gen import Model, coordinates, parameters
    runs = Path(__file__).with_suffix(".runs")
    runs.write_text(runs.read_text() + "x" if runs.exists() else "x")

    def build(k0=2.0):
        x = coordinates("x")
        k = parameters("k", defaults=(float(k0),))
        return Model("counted_spring", coords=[x], T=x.d**2 / 2, V=k * x**2 / 2)
    """)


def _runs(path):
    counter = path.with_suffix(".runs")
    return len(counter.read_text()) if counter.exists() else 0


def _spring(tmp_path, text=SPRING):
    path = tmp_path / "counted_spring.py"
    path.write_text(text)
    return path


def test_second_load_imports_without_running_the_model_file(tmp_path):
    path, out = _spring(tmp_path), tmp_path / "gen"
    first = load(path, out_dir=out, methods=["rk4"])
    ran = _runs(path)
    assert ran >= 1
    again = load(path, out_dir=out, methods=["rk4"])
    assert again is first and _runs(path) == ran
    assert load(path, out_dir=out) is first and _runs(path) == ran     # any methods: it has rk4


def test_an_edited_model_file_runs_and_regenerates(tmp_path):
    path, out = _spring(tmp_path), tmp_path / "gen"
    load(path, out_dir=out, methods=["rk4"])
    ran = _runs(path)
    path.write_text(SPRING.replace("defaults=(float(k0),)", "defaults=(float(k0) + 1,)"))
    mod = load(path, out_dir=out, methods=["rk4"])
    assert _runs(path) > ran
    assert mod.DEFAULTS == (3.0,)


def test_other_build_options_or_a_missing_method_run_the_file(tmp_path):
    """Not served from the cache: other build options (the module on disk has the defaults, so
    load refuses in one line as it always did) and a method the module lacks (added)."""
    import pytest
    from lagrange_gen.errors import GenerationError
    path, out = _spring(tmp_path), tmp_path / "gen"
    load(path, out_dir=out, methods=["rk4"])
    ran = _runs(path)
    with pytest.raises(GenerationError, match="--set k0=5.0"):
        load(path, out_dir=out, methods=["rk4"], options={"k0": 5.0})
    assert _runs(path) > ran
    ran = _runs(path)
    mod = load(path, out_dir=out, methods=["midpoint"])
    assert _runs(path) > ran and {"rk4", "midpoint"} <= set(mod.METHODS)
    ran = _runs(path)
    assert load(path, out_dir=out, methods=["midpoint"]) is mod and _runs(path) == ran


def test_a_hand_edited_module_is_not_served_from_the_cache(tmp_path):
    """The cache hands out only what the ordinary way would: an edited module is refused by the
    check every import runs (StaleModuleError from the module), after the file ran again."""
    import pytest
    from lagrange_gen.errors import StaleModuleError
    path, out = _spring(tmp_path), tmp_path / "gen"
    mod = load(path, out_dir=out, methods=["rk4"])
    target = out / "counted_spring.py"
    assert model_cache.current_module(path, out, ["rk4"]) == target
    target.write_text(target.read_text().replace("DO NOT EDIT", "DO NOT EDIT!"))
    assert model_cache.current_module(path, out, ["rk4"]) is None
    del mod


def test_a_fresh_process_loads_without_running_the_file_or_importing_sympy(tmp_path):
    path, out = _spring(tmp_path), tmp_path / "gen"
    load(path, out_dir=out, methods=["rk4"])
    ran = _runs(path)
    code = ("import sys, lagrange_gen as lg\n"
            f"m = lg.load({str(path)!r}, out_dir={str(out)!r}, methods=['rk4'])\n"
            "print(m.NAME, 'sympy' in sys.modules)\n")
    out_text = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out_text.split() == ["counted_spring", "False"]
    assert _runs(path) == ran


DATA_SPRING = textwrap.dedent("""\
    import json
    from pathlib import Path
    from lagrange_gen import Model, coordinates, parameters
    here = Path(__file__)
    runs = here.with_suffix(".runs")
    runs.write_text(runs.read_text() + "x" if runs.exists() else "x")
    k0 = json.loads(here.with_name("stiffness.json").read_text())["k"]
    x = coordinates("x")
    k = parameters("k", defaults=(float(k0),))
    model = Model("data_spring", coords=[x], T=x.d**2 / 2, V=k * x**2 / 2)
    """)


def test_a_model_that_reads_a_data_file_is_served_until_the_file_changes(tmp_path):
    """The data files a model read are part of what the cache compares (their record, from the
    generation): unchanged, load does not run the file; changed, it runs it and regenerates."""
    import os
    path = tmp_path / "data_spring.py"
    path.write_text(DATA_SPRING)
    data = tmp_path / "stiffness.json"
    data.write_text('{"k": 2.0}')
    out = tmp_path / "gen"
    first = load(path, out_dir=out, methods=["rk4"])
    ran = _runs(path)
    assert load(path, out_dir=out, methods=["rk4"]) is first and _runs(path) == ran
    before = data.stat().st_mtime_ns
    data.write_text('{"k": 5.0}')
    os.utime(data, ns=(before + 10**9, before + 10**9))
    mod = load(path, out_dir=out, methods=["rk4"])
    assert _runs(path) > ran
    assert mod.DEFAULTS == (5.0,)


def test_generating_runs_the_model_file_once(tmp_path):
    """load() decides what to generate from the Model the file gives and hands that Model to
    the generator: a missing module, a stale one and a missing method each run the file once."""
    path, out = _spring(tmp_path), tmp_path / "gen"
    load(path, out_dir=out, methods=["rk4"])
    assert _runs(path) == 1
    load(path, out_dir=out, methods=["rk4", "midpoint"])
    assert _runs(path) == 2
    path.write_text(SPRING.replace("defaults=(float(k0),)", "defaults=(float(k0) + 1,)"))
    assert load(path, out_dir=out, methods=["rk4"]).DEFAULTS == (3.0,)
    assert _runs(path) == 3
