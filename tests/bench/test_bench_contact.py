"""`lagrange-gen bench contact --quick` through the CLI on a model directory holding the bouncing
ball, the rocking block and the puck on a table: the report names both methods and the three
cases, says whether Siconos ran, and draws its figure; the event-driven runs' errors against the
closed forms are small (the bouncing ball's parabolas and the puck's straight deceleration are
exact between located switches). No timing asserts."""

import re
import shutil

import matplotlib.image as mpimg
import numpy as np

from lg_test_support import MODELS_DIR
from lagrange_gen.cli.main import main


def test_bench_contact_quick_writes_its_report(tmp_path, gen_dir, monkeypatch):
    models = tmp_path / "models"
    models.mkdir()
    for stem in ("bouncing_ball", "rocking_block", "puck_on_table"):
        shutil.copy(MODELS_DIR / f"{stem}.py", models)
    (tmp_path / "generated").symlink_to(gen_dir)
    monkeypatch.chdir(tmp_path)
    assert main(["bench", "contact", "--quick", "--no-progress", "--models", "models",
                 "--reports", "reports"]) == 0
    text = (tmp_path / "reports" / "contact.md").read_text()
    assert text.startswith("# Contact and impacts: work-precision")
    assert "## Bouncing ball" in text and "## Rocking block" in text and "## Puck" in text
    assert "Siconos" in text
    rows = re.findall(r"\| dop853_impacts \| \S+ \| \S+ \| (\S+) \|", text)
    assert len(rows) == 6
    assert float(rows[0]) <= 1e-9                 # the ball: exact parabolas, located impacts
    assert float(rows[3]) <= 1e-6                 # the block at rtol 1e-8
    assert max(float(rows[4]), float(rows[5])) <= 1e-9      # the puck: a located stop
    assert len(re.findall(r"\| moreau_jean \|", text)) == 6
    figure = tmp_path / "reports" / "contact_precision.png"
    assert figure.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert float(np.ptp(mpimg.imread(figure)[..., :3])) > 0.0       # not a blank image
