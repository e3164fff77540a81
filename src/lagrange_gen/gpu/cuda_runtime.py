"""numba-cuda, imported only when device="cuda" is asked for, and the one-line refusals.

numba-cuda 0.30 registers an overload of ``np.row_stack`` at import; NumPy 2.5 removed that
alias, so on such a NumPy the import fails. restore_row_stack puts the alias back (it is
np.vstack) before the import, only when it is missing.
"""

from __future__ import annotations

from ..errors import SimulationError

#: What to install for device="cuda".
INSTALL_HINT = "pip install 'lagrange-gen[gpu]' (numba-cuda)"


def restore_row_stack():
    """np.row_stack = np.vstack when NumPy no longer has it (numba-cuda's import needs it)."""
    import numpy as np
    if not hasattr(np, "row_stack"):
        np.row_stack = np.vstack


def import_cuda():
    """numba.cuda (the real target or numba's simulator); SimulationError (one line) when
    numba-cuda is not installed or fails to import."""
    restore_row_stack()
    try:
        from numba import cuda
    except ImportError as exc:
        raise SimulationError(f"device='cuda' needs numba-cuda, which is not installed "
                              f"({_first_line(exc)}): {INSTALL_HINT}") from None
    except Exception as exc:        # a broken install: still one line, never a traceback
        raise SimulationError(f"device='cuda': numba-cuda failed to import: "
                              f"{_first_line(exc)}") from None
    return cuda


def load_cuda():
    """numba.cuda ready to launch: a GPU with its driver, or the simulator. SimulationError
    (one line) saying what is missing otherwise."""
    cuda = import_cuda()
    if is_simulator(cuda):
        return cuda
    try:
        cuda.get_current_device()
    except Exception as exc:
        raise SimulationError(f"device='cuda': no usable CUDA GPU ({_first_line(exc)}); run "
                              f"with device='cpu', or set NUMBA_ENABLE_CUDASIM=1 to run numba's "
                              f"CUDA simulator (slow: for tests)") from None
    return cuda


def is_simulator(cuda) -> bool:
    """True when ``cuda`` (numba.cuda) is numba's CUDA simulator."""
    from numba import config
    return bool(getattr(config, "ENABLE_CUDASIM", 0))


def device_name(cuda) -> str:
    """The GPU's name, or "CUDA simulator"."""
    if is_simulator(cuda):
        return "numba CUDA simulator (CPU)"
    name = cuda.get_current_device().name
    return name.decode() if isinstance(name, bytes) else str(name)


def gpu_present() -> tuple[bool, str]:
    """(True, GPU name) when a real CUDA GPU can be used, else (False, why not): for the bench,
    which must not measure the simulator."""
    try:
        cuda = load_cuda()
    except SimulationError as exc:
        return False, str(exc)
    if is_simulator(cuda):
        return False, "NUMBA_ENABLE_CUDASIM=1: numba's CUDA simulator, not a GPU"
    return True, device_name(cuda)


def _first_line(exc) -> str:
    """The first non-empty line of an exception's text (driver errors span several)."""
    lines = [" ".join(line.split()) for line in str(exc).splitlines()]
    text = " ".join(line for line in lines if line)
    return (text[:200] + "...") if len(text) > 200 else (text or type(exc).__name__)
