"""Generated files: deterministic, keyed, atomic, refused when stale."""

import os
import shutil
import subprocess
import sys

import pytest

from lg_test_support import MODELS_DIR, ROOT
from lagrange_gen import StaleModuleError
from lagrange_gen.codegen import generate_model
from lagrange_gen.codegen.keys import read_key
from lagrange_gen.run.loader import import_generated


def test_second_run_is_byte_identical_even_with_another_hash_seed(tmp_path):
    first = generate_model(MODELS_DIR / "double_pendulum.py", tmp_path / "a")
    text = first.path.read_bytes()
    again = generate_model(MODELS_DIR / "double_pendulum.py", tmp_path / "a")
    assert not again.written and again.path.read_bytes() == text
    first.path.unlink()  # the file records its output dir and model path: regenerate in place
    env = dict(os.environ, PYTHONHASHSEED="12345")
    subprocess.run([sys.executable, "-m", "lagrange_gen.cli", str(MODELS_DIR / "double_pendulum.py"),
                    "-o", str(tmp_path / "a")], check=True, env=env, cwd=ROOT, capture_output=True)
    assert first.path.read_bytes() == text


def test_changed_model_changes_key_and_stale_module_is_refused(tmp_path):
    model = tmp_path / "models" / "pend.py"
    model.parent.mkdir()
    shutil.copy(MODELS_DIR / "cart_pendulum.py", model)
    out = tmp_path / "gen"
    first = generate_model(model, out)
    assert read_key(first.path) == first.key
    model.write_text(model.read_text().replace("defaults=(1.0, 0.5,", "defaults=(2.0, 0.5,"))
    with pytest.raises(StaleModuleError, match=r"run lagrange-gen .*pend\.py"):
        import_generated(first.path)
    second = generate_model(model, out)
    assert second.written and second.key != first.key
    mod = import_generated(second.path)
    assert mod.DEFAULTS[0] == 2.0 and mod.KEY == second.key


def test_hand_edited_file_is_refused(tmp_path):
    result = generate_model(MODELS_DIR / "cart_pendulum.py", tmp_path)
    text = result.path.read_text().replace('KEY = "', 'KEY = "0', 1)
    result.path.write_text(text)
    with pytest.raises(StaleModuleError, match="run lagrange-gen"):
        import_generated(result.path)


def test_generated_module_carries_orderings_and_key(generated):
    mod = generated("cart_pendulum")
    assert mod.COORDS == ("x", "theta") and mod.PARAMS == ("M", "m", "l", "k", "g")
    assert mod.DEFAULTS == (1.0, 0.5, 1.0, 10.0, 9.81)
    assert mod.N_COORDS == 2 and mod.N_CONSTRAINTS == 0
    assert "0: x" in mod.__doc__ and "4: g = 9.81" in mod.__doc__
    assert read_key(mod.__file__) == mod.KEY


def test_constraint_kernel_of_cartesian_pendulum(generated):
    import numpy as np
    mod = generated("cartesian_pendulum")
    q, qd = np.array([0.6, -0.8]), np.array([0.8, 0.6])
    phi, J, gamma = np.empty(1), np.empty((1, 2)), np.empty(1)
    mod.constraints(q, qd, 0.0, mod.DEFAULT_PARAMS, phi, J, gamma)
    # Phi = (x^2 + y^2 - l^2)/2, J = (x, y), gamma = -(xd^2 + yd^2)
    np.testing.assert_allclose(phi, [0.0], atol=1e-15)
    np.testing.assert_allclose(J, [[0.6, -0.8]], rtol=1e-15)
    np.testing.assert_allclose(gamma, [-1.0], rtol=1e-15)
