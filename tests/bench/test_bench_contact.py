"""`lagrange-gen bench contact --quick` through the CLI on a model directory holding the bouncing
ball, the rocking block and the puck on a table: the report names the three methods and the three
cases, says whether Siconos ran, and draws its figure; the event-driven runs' errors against the
closed forms are small (the bouncing ball's parabolas and the puck's straight deceleration are
exact between located switches). No timing asserts, so the runs take the portable loops (one
compile per method, not one per model and method)."""

import re
import shutil

import matplotlib.image as mpimg
import numpy as np

from lg_test_support import MODELS_DIR
from lagrange_gen.cli.main import main
from lagrange_gen.jit.portable import JIT_ENV


def test_bench_contact_quick_writes_its_report(tmp_path, gen_dir, monkeypatch):
    models = tmp_path / "models"
    models.mkdir()
    for stem in ("bouncing_ball", "rocking_block", "puck_on_table"):
        shutil.copy(MODELS_DIR / f"{stem}.py", models)
    (tmp_path / "generated").symlink_to(gen_dir)
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv(JIT_ENV, "portable")
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
    # spook_contacts at the same steps (an order-1 method at h = t_end / 100 and / 50): each
    # run's error below the ball's drop height, the block's energy fraction and a tenth of the
    # puck's sliding distance (0.68 m)
    spook = [float(x) for x in re.findall(r"\| spook_contacts \| \S+ \| \S+ \| (\S+) \|", text)]
    assert len(spook) == 6 and max(spook[:2]) < 1.0 and max(spook[2:4]) < 0.5
    assert max(spook[4:]) < 0.068
    figure = tmp_path / "reports" / "contact_precision.png"
    assert figure.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert float(np.ptp(mpimg.imread(figure)[..., :3])) > 0.0       # not a blank image


def test_slider_crank_row_compares_with_siconos_reference(gen_dir):
    """The slider-crank with clearance case of bench contact: Siconos' published reference
    (the last row of SliderCrankMoreauJeanDirectProjectionOSI.ref: 3.064804887294570 crank
    revolutions at t = 0.2) and the sweep's dop853_impacts run reaching t_end (it stopped at
    t = 0.034 before the exact contact solver) within 0.25 revolutions of it (measured 0.187:
    the two methods' impact sequences differ, see bench/contact.py)."""
    from lagrange_gen.analysis import runs
    from lagrange_gen.bench import common
    from lagrange_gen.bench.contact import (CASES, SICONOS_SLIDER_CRANK_REVOLUTIONS, Settings,
                                            sweep)
    assert SICONOS_SLIDER_CRANK_REVOLUTIONS == 3.064804887294570
    case = next(c for c in CASES if c.stem == "slider_crank_clearance")
    mod = runs.load_module(MODELS_DIR, case.stem, gen_dir)
    settings = Settings(n0=2000, k_max=-1, rtols=(1e-8,), repeats=1, budget=60.0)
    points = sweep(mod, case, settings, common.Progress(1, "contact", enabled=False))
    assert [pt.method for pt in points] == ["dop853_impacts"]
    assert not points[0].failed and points[0].error <= 0.25


def test_woodpecker_row_compares_with_siconos_reference(gen_dir):
    """The woodpecker case: Siconos' reference sleeve height at t = 0.29998 (the last row of
    Woodpecker.ref, -0.04134818676833654), and the sweep's dop853_impacts (rtol 1e-8) and
    moreau_jean (h = t_end / 15000 = 2e-5, Siconos' step) runs end within 1e-4 of it
    (measured 2.5e-5 and 3.0e-6 on a descent of 41 mm)."""
    from lagrange_gen.analysis import runs
    from lagrange_gen.bench import common
    from lagrange_gen.bench.contact import CASES, SICONOS_WOODPECKER_Y, Settings, sweep
    assert SICONOS_WOODPECKER_Y == -4.134818676833654e-02
    case = next(c for c in CASES if c.stem == "woodpecker")
    mod = runs.load_module(MODELS_DIR, case.stem, gen_dir)
    settings = Settings(n0=15000, k_max=0, rtols=(1e-8,), repeats=1, budget=60.0)
    points = sweep(mod, case, settings, common.Progress(1, "contact", enabled=False))
    by_method = {pt.method: pt for pt in points}
    for method in ("dop853_impacts", "moreau_jean"):
        assert not by_method[method].failed and by_method[method].error <= 1e-4, method
