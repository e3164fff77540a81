"""End-to-end smoke test of `lagrange-gen bench` through the CLI (tests never import the bench):
the stability suite on a model directory holding only the damped oscillator writes its report
and figure, with the measured stability intervals of HARD_CASES case 3 in it. The glue of the
oscillator comes from the session's generated directory (warm when the analysis tests ran
first). No timing asserts."""

import shutil

import matplotlib.image as mpimg
import numpy as np

from lg_test_support import MODELS_DIR
from lagrange_gen.cli.main import main


def png_has_pixels(path, min_bytes=2000):
    """True when path is a PNG of some size whose pixels are not all one colour."""
    if not path.is_file() or path.stat().st_size < min_bytes:
        return False
    if path.read_bytes()[:8] != b"\x89PNG\r\n\x1a\n":
        return False
    return float(np.ptp(mpimg.imread(path)[..., :3])) > 0.0


def test_bench_stability_quick_writes_its_report(tmp_path, gen_dir, monkeypatch):
    models = tmp_path / "models"
    models.mkdir()
    shutil.copy(MODELS_DIR / "damped_oscillator.py", models)
    (tmp_path / "generated").symlink_to(gen_dir)      # the bench generates into ./generated
    monkeypatch.chdir(tmp_path)
    code = main(["bench", "stability", "--quick", "--no-progress", "--models", "models",
                 "--reports", "reports"])
    assert code == 0
    text = (tmp_path / "reports" / "stability.md").read_text()
    assert text.startswith("# Linear stability")
    # Measured intervals on the grid (TAUS puts 1.99 and 2.01 around Verlet's limit tau = 2).
    assert "| verlet | tau <= 1.99 (grid point) |" in text
    assert "| explicit_euler | no tau > 0 |" in text
    assert "| midpoint | every measured tau |" in text
    # Scenes whose model is not in the directory are reported, not crashed on.
    assert "four-bar linkage" in text and "not available in this build" in text
    assert png_has_pixels(tmp_path / "reports" / "stability_tau.png")


def test_scale_report_names_the_dominant_stage():
    from lagrange_gen.bench.scale_report import dominant_stage
    row = {"derive": 0.5, "emit": 1.5, "kernels_compile": 6.0, "glue_compile": 2.0}
    assert dominant_stage(row) == "kernel compile (60 %)"
    row["glue_compile"] = 12.0
    assert dominant_stage(row) == "glue compile (60 %)"
