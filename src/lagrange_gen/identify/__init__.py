"""Parameter identification from measured responses (Lamarque's lecture, sources/001).

Two identifications, each from one sampled signal:

- :func:`identify_prandtl`: stiffnesses k0, k_i and thresholds eta_i of the generalized Prandtl
  model with linear hardening, from a loading half-cycle (or full cycles) in the (x, F - m x'')
  plane, whose slope changes sit at 2 eta_j from the turning point (module :mod:`.prandtl`);
- :func:`identify_damping`: viscous damping from a free decay by the wavelet logarithmic decrement
  (module :mod:`.damping`, needs PyWavelets).

Data that cannot be identified raise :class:`IdentificationError` with a one-line message that says
what is missing. ``lagrange-gen identify data.csv --kind prandtl|damping`` is the command line
(:mod:`.cli`).
"""

from .damping import DampingFit, identify_damping
from ..errors import IdentificationError
from .prandtl import PrandtlFit, identify_prandtl, loading_branch
from .wavelet import wavelet_breakpoints

__all__ = ["IdentificationError", "PrandtlFit", "identify_prandtl", "loading_branch",
           "DampingFit", "identify_damping", "wavelet_breakpoints"]
