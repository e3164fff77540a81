"""`lagrange-gen examples`: the example models (models/*.py) list and copy from an installed
package as from this checkout, and setup.py's build step puts them into the package."""

import subprocess
import sys
from pathlib import Path

from lagrange_gen.cli.examples import example_files, examples_dir
from lagrange_gen.cli.main import main, generate_parser

ROOT = Path(__file__).resolve().parents[2]


def test_every_model_is_an_example_and_the_list_shows_each_with_its_summary(capsys):
    models = sorted(p.stem for p in (ROOT / "models").glob("*.py"))
    assert sorted(example_files()) == models
    assert main(["examples"]) == 0
    out = capsys.readouterr().out
    for name in models:
        assert any(line.split()[:1] == [name] for line in out.splitlines()), name
    assert "Pendulum on a spring-restrained cart" in out


def test_copy_one_into_a_folder_and_refuse_to_overwrite(tmp_path, capsys):
    target = tmp_path / "mine"
    assert main(["examples", "cart_pendulum", "--to", str(target)]) == 0
    copied = target / "cart_pendulum.py"
    assert copied.read_bytes() == (ROOT / "models" / "cart_pendulum.py").read_bytes()
    assert f"lagrange-gen {copied}" in capsys.readouterr().out
    copied.write_text("# mine now\n")
    assert main(["examples", "cart_pendulum", "--to", str(target)]) == 2
    err = capsys.readouterr().err.strip()
    assert "exists" in err and "--force" in err and len(err.splitlines()) == 1
    assert copied.read_text() == "# mine now\n"
    assert main(["examples", "cart_pendulum", "--to", str(target), "--force"]) == 0
    assert copied.read_bytes() == (ROOT / "models" / "cart_pendulum.py").read_bytes()


def test_an_unknown_name_is_one_line_naming_the_nearest(capsys):
    assert main(["examples", "cart_pendulm"]) == 2
    err = capsys.readouterr().err.strip()
    assert "no example 'cart_pendulm'" in err and "cart_pendulum" in err
    assert len(err.splitlines()) == 1


def test_help_points_to_the_examples_command():
    text = generate_parser().format_help()
    assert "lagrange-gen examples" in text
    assert "(see models/cart_pendulum.py)" not in text


def test_the_build_step_ships_the_models_in_the_package(tmp_path):
    build = tmp_path / "build"
    subprocess.run([sys.executable, "setup.py", "-q", "build_py", "--build-lib", str(build)],
                   cwd=ROOT, check=True, capture_output=True, text=True, timeout=300)
    shipped = build / "lagrange_gen" / "example_models"
    assert sorted(p.name for p in shipped.glob("*.py")) == sorted(
        p.name for p in (ROOT / "models").glob("*.py"))
    # an installed package finds them beside its modules
    assert examples_dir(build / "lagrange_gen") == shipped
