"""A model file that calls os._exit while loading is one error line, and a batch goes on; it
ended the whole process with its exit code, a batch with exit 0 (issue 34, item 8). Run in a
subprocess: without the fix it would end the test process."""

import subprocess
import sys
from pathlib import Path

MODELS_DIR = Path(__file__).resolve().parents[2] / "models"


def test_os_exit_in_a_model_file_is_an_error_and_the_batch_goes_on(tmp_path):
    bad = tmp_path / "quits.py"
    bad.write_text("import os\nos._exit(0)\n")
    code = ("import sys; from lagrange_gen.cli.main import main; "
            "sys.exit(main(sys.argv[1:]))")
    out = subprocess.run([sys.executable, "-c", code, "--check", "-o", str(tmp_path / "gen"),
                          str(bad), str(MODELS_DIR / "damped_oscillator.py")],
                         capture_output=True, text=True, timeout=300)
    assert out.returncode != 0, (out.stdout, out.stderr)
    assert "quits.py:2" in out.stderr and "os._exit" in out.stderr, out.stderr
    assert "Traceback" not in out.stderr
    assert "damped_oscillator" in out.stdout + out.stderr        # the batch went on
