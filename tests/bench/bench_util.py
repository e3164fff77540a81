"""Helpers of the bench tests (no conftest.py here: a second conftest module would shadow the
top-level one). Models are generated once per process into a temporary directory."""

import atexit
import shutil
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
MODELS = ROOT / "models"
_DIR = []


def gen_dir():
    """A per-process temporary directory for generated modules (removed at exit)."""
    if not _DIR:
        _DIR.append(Path(tempfile.mkdtemp(prefix="lagrange_gen_bench_tests_")))
        atexit.register(shutil.rmtree, _DIR[0], True)
    return _DIR[0]


def module(stem, **options):
    from lagrange_gen.bench import common
    return common.load_module(MODELS, stem, gen_dir(), **options)


def png_ok(path, min_bytes=2000):
    """True when path is a PNG file of some size whose pixels are not all one colour."""
    import matplotlib.image as mpimg
    path = Path(path)
    if not path.is_file() or path.stat().st_size < min_bytes:
        return False
    if path.read_bytes()[:8] != b"\x89PNG\r\n\x1a\n":
        return False
    img = mpimg.imread(path)
    return float(np.ptp(img[..., :3])) > 0.0
