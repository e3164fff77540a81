"""The package's own attributes: __version__ and dir()."""
import importlib.metadata
import shutil
import subprocess
import sys
import tomllib

import lagrange_gen
from lg_test_support import ROOT


def test_version_is_the_project_version():
    declared = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["version"]
    assert lagrange_gen.__version__ == declared
    assert lagrange_gen.__version__ == importlib.metadata.version("lagrange-gen")


def test_version_without_installed_metadata_is_a_valid_placeholder(tmp_path):
    # A copy of the package on a path with no distribution metadata, in an interpreter without
    # site-packages: nothing records a version.
    shutil.copytree(ROOT / "src" / "lagrange_gen", tmp_path / "lagrange_gen",
                    ignore=shutil.ignore_patterns("__pycache__"))
    code = (f"import sys; sys.path.insert(0, {str(tmp_path)!r}); import lagrange_gen; "
            "print(lagrange_gen.__file__); print(lagrange_gen.__version__)")
    done = subprocess.run([sys.executable, "-S", "-c", code], capture_output=True, text=True,
                          env={"PATH": "/usr/bin:/bin"}, check=True)
    where, version = done.stdout.split()
    assert where.startswith(str(tmp_path))
    assert version == "0+unknown"


def test_dir_lists_the_lazy_api_before_it_is_loaded():
    code = ("import sys, lagrange_gen; names = dir(lagrange_gen); "
            "print(all(n in names for n in lagrange_gen.__all__ + ['__version__']), "
            "'lagrange_gen.run.simulate' in sys.modules, 'sympy' in sys.modules)")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          check=True, cwd=ROOT)
    assert done.stdout.split() == ["True", "False", "False"]


def test_every_public_name_in_dir_resolves():
    public = [name for name in dir(lagrange_gen) if not name.startswith("_")]
    assert {"Model", "simulate", "ensemble", "Trajectory", "Stepper", "linearize"} <= set(public)
    for name in public:
        assert getattr(lagrange_gen, name) is not None, name
