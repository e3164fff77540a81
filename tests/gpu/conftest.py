"""tests/gpu: lagrange_gen.ensemble(..., device="cuda") against the CPU ensemble.

Without a GPU they run under numba's CUDA simulator (set here unless NUMBA_ENABLE_CUDASIM is
already in the environment); on a machine with a GPU, ``NUMBA_ENABLE_CUDASIM=0 pytest tests/gpu``
runs the same tests on the device. Each file skips, with the reason, when numba-cuda is not
installed (``pip install -e '.[test]'`` installs it).
"""

import os

os.environ.setdefault("NUMBA_ENABLE_CUDASIM", "1")

try:
    import numba
except ImportError:          # (the package needs numba: nothing else here runs then either)
    numba = None
else:
    # numba reads the variable when it is first imported, and another test file of this
    # process may have imported it already; numba.cuda, imported only by these tests, reads
    # the config attribute.
    numba.config.ENABLE_CUDASIM = int(os.environ["NUMBA_ENABLE_CUDASIM"] not in ("", "0"))
